// The measurement log: "driftless-log 1", a CSV file with '# key: value' metadata.
// Format reference: docs/log-format.md. Reader and writer stream at constant memory.
#pragma once

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "estimator/input_error.hpp"
#include "estimator/sample.hpp"

namespace driftless::log {

inline constexpr std::string_view kFormatId = "driftless-log 1";

/// A malformed or unreadable log: the one input-error type, naming the file, line and key.
using LogError = InputError;

/// Ordered '# key: value' metadata. Keys are unique; values are kept as text.
class Metadata {
 public:
  void set(std::string key, std::string value);
  std::optional<std::string> get(std::string_view key) const;
  bool has(std::string_view key) const { return get(key).has_value(); }
  /// Numeric value of key, or fallback when absent; throws LogError (naming `where`) if not a number.
  double get_number(std::string_view key, double fallback, std::string_view where = {}) const;
  /// A 3-vector "x y z", or fallback when absent.
  Eigen::Vector3d get_vector3(std::string_view key, const Eigen::Vector3d& fallback,
                              std::string_view where = {}) const;
  const std::vector<std::pair<std::string, std::string>>& entries() const { return entries_; }

  // the standard keys, with their defaults
  double sample_rate_hz() const { return get_number("sample_rate_hz", kNaN); }
  double latitude_deg() const { return get_number("latitude_deg", kNaN); }
  bool complete() const;
  Eigen::Vector3d hinge1_axis() const { return get_vector3("hinge1_axis", Eigen::Vector3d::UnitZ()); }
  Eigen::Vector3d hinge2_axis() const { return get_vector3("hinge2_axis", Eigen::Vector3d::UnitX()); }

 private:
  std::vector<std::pair<std::string, std::string>> entries_;
};

/// A '# event: ...' line found between rows (a source switch, a gap, a fault).
struct Event {
  double t_s = kNaN;     // time of the row before the event line (NaN before the first row)
  std::string text;      // the text after '# event:'
  std::size_t line = 0;  // 1-based line number in the file
};

/// The column names a log with the given optional fields carries, in writing order.
std::vector<std::string> column_names(std::uint32_t fields);

/// Streams samples into a log file. The header says 'complete: false' until finish(true) succeeds,
/// so a crash, Ctrl-C or a vanished device never leaves a file that looks whole and is not.
/// Rows reach the disk in whole-row chunks: a killed process leaves only complete rows.
class LogWriter {
 public:
  /// Opens `path` for writing (throws std::runtime_error naming the path on failure).
  LogWriter(const std::filesystem::path& path, const Metadata& meta, std::uint32_t fields);
  ~LogWriter();
  LogWriter(const LogWriter&) = delete;
  LogWriter& operator=(const LogWriter&) = delete;

  /// Appends one row. Values absent from `fields` are not written; NaN is written as empty.
  void write(const Sample& s);
  /// Appends a '# event: t=<t> <text>' line (switch-over, gap, fault).
  void event(double t_s, std::string_view text);
  /// Pushes buffered rows to the file (the OS), so a reader or a crash sees them.
  void flush();
  /// Flushes and closes. With complete=true the header is patched to 'complete: true';
  /// otherwise a '# incomplete: <reason>' trailer is written and the header stays false.
  void finish(bool complete, std::string_view reason = {});

  std::uint64_t rows_written() const { return rows_; }
  const std::filesystem::path& path() const { return path_; }

 private:
  void append_row(const Sample& s);
  std::filesystem::path path_;
  std::FILE* file_ = nullptr;
  std::uint32_t fields_ = 0;
  long complete_offset_ = -1;  // byte offset of the value of 'complete:' in the header
  std::string buffer_;
  std::uint64_t rows_ = 0;
  bool finished_ = false;
};

/// Reader options.
struct ReaderOptions {
  /// Accept a last row cut off mid-line when the log says 'complete: false' (else it is an error).
  bool tolerate_truncated_tail = true;
};

/// Streams samples out of a log file, validating as it goes. Errors name file and line.
class LogReader {
 public:
  explicit LogReader(const std::filesystem::path& path, ReaderOptions opts = {});
  ~LogReader();
  LogReader(const LogReader&) = delete;
  LogReader& operator=(const LogReader&) = delete;

  const Metadata& metadata() const { return meta_; }
  /// Optional column groups present (SampleField bits); a group counts only when complete.
  std::uint32_t fields() const { return fields_; }
  const std::vector<std::string>& columns() const { return columns_; }
  /// Index of a column by name (any column, also unknown ones), or -1.
  int column_index(std::string_view name) const;

  /// Reads the next row into `out`. Returns false at the end of the file.
  /// Throws LogError (file:line: what was expected) on a malformed row or non-increasing t.
  bool next(Sample& out);
  /// Raw value of column `index` in the row last read (NaN when empty).
  double value(int index) const { return row_[static_cast<std::size_t>(index)]; }

  std::uint64_t rows_read() const { return rows_; }
  const std::vector<Event>& events() const { return events_; }
  /// True if the file ended in a partial row that was dropped (only for incomplete logs).
  bool dropped_truncated_row() const { return dropped_truncated_; }
  /// Number of rows holding a NaN or empty gyro value (they are returned; callers skip them).
  std::uint64_t rows_with_missing_gyro() const { return missing_gyro_rows_; }
  /// "file:line" for messages.
  std::string where() const;
  const std::filesystem::path& path() const { return path_; }

 private:
  bool read_line(std::string_view& line);
  [[noreturn]] void fail(std::string_view what) const;
  void parse_header_line(std::string_view line);

  std::filesystem::path path_;
  ReaderOptions opts_;
  std::FILE* file_ = nullptr;
  std::string buf_;
  std::size_t buf_pos_ = 0;
  bool eof_ = false;
  bool last_line_unterminated_ = false;
  std::size_t line_no_ = 0;
  Metadata meta_;
  std::vector<std::string> columns_;
  std::uint32_t fields_ = 0;
  std::vector<int> slot_of_column_;  // column -> slot in Sample (or -1 for unknown)
  std::vector<double> row_;
  std::vector<Event> events_;
  std::uint64_t rows_ = 0;
  std::uint64_t missing_gyro_rows_ = 0;
  double last_t_ = -std::numeric_limits<double>::infinity();
  bool dropped_truncated_ = false;
};

/// Reads a whole log into memory (for short logs and tests).
std::vector<Sample> read_all(const std::filesystem::path& path, Metadata* meta = nullptr,
                             std::uint32_t* fields = nullptr);

}  // namespace driftless::log
