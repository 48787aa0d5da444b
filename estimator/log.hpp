// The measurement log: "driftless-log 1", a CSV file with '# key: value' metadata.
// Format reference: docs/log-format.md. Reader and writer stream at constant memory; the one
// validation of a log (metadata values, gyro plausibility, time gaps) lives in the reader, so
// every command that reads a log (check included) refuses and reports the same things.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "estimator/clip_detector.hpp"
#include "estimator/input_error.hpp"
#include "estimator/output_file.hpp"
#include "estimator/sample.hpp"

namespace driftless::log {

inline constexpr std::string_view kFormatId = "driftless-log 1";

/// Gyro plausibility bound (deg/s) for a log that states no gyro_full_scale_dps: the largest range
/// of common MEMS gyros (+-4000 deg/s). A value beyond kFullScaleMargin times the full scale cannot
/// come from the sensor and is refused.
inline constexpr double kDefaultGyroFullScaleDps = 4000.0;
inline constexpr double kFullScaleMargin = 1.1;

/// Time gaps: driftless::gap_threshold_s (estimator/sample.hpp), with the shortest interval so far
/// standing for the sample interval when the log states no rate.
using driftless::kGapMinS;

/// A malformed or unreadable log: the one input-error type, naming the file, line and key.
using LogError = InputError;

/// Ordered '# key: value' metadata. Keys are unique; values are kept as text, with the line they
/// came from (0 when set by a program).
class Metadata {
 public:
  void set(std::string key, std::string value, std::size_t line = 0);
  std::optional<std::string> get(std::string_view key) const;
  bool has(std::string_view key) const { return find(key) != nullptr; }
  /// Line of key in the file it was read from (0 when unknown).
  std::size_t line_of(std::string_view key) const;
  /// Numeric value of key, or fallback when absent; throws LogError (naming `where`) if not a number.
  double get_number(std::string_view key, double fallback, std::string_view where = {}) const;
  /// A 3-vector "x y z", or fallback when absent.
  Eigen::Vector3d get_vector3(std::string_view key, const Eigen::Vector3d& fallback,
                              std::string_view where = {}) const;
  const std::vector<std::pair<std::string, std::string>>& entries() const { return entries_; }

  // the standard keys (docs/log-format.md), with their defaults; validate_metadata() checked them
  double sample_rate_hz() const { return get_number("sample_rate_hz", kNaN); }
  double latitude_deg() const { return get_number("latitude_deg", kNaN); }
  bool complete() const;
  Eigen::Vector3d hinge1_axis() const { return get_vector3("hinge1_axis", Eigen::Vector3d::UnitZ()); }
  Eigen::Vector3d hinge2_axis() const { return get_vector3("hinge2_axis", Eigen::Vector3d::UnitX()); }
  /// The gyro full scale the log states (deg/s), else kDefaultGyroFullScaleDps.
  double gyro_full_scale_dps() const { return get_number("gyro_full_scale_dps", kDefaultGyroFullScaleDps); }
  /// The key that states sensor `sensor`'s (1 or 2) full scale: gyro1_/gyro2_full_scale_dps when
  /// present (two unlike gyros), else the shared gyro_full_scale_dps; empty when neither is there.
  std::string_view gyro_full_scale_key(int sensor) const;
  /// Sensor `sensor`'s full scale (deg/s): its own key, else the shared one, else the default.
  double gyro_full_scale_dps(int sensor) const;
  /// 1 for the single-sensor form ('sensors: 1'), else 2.
  int sensors() const;

 private:
  const std::string* find(std::string_view key) const;
  std::vector<std::pair<std::string, std::string>> entries_;
  std::vector<std::size_t> lines_;
};

/// Checks every standard key's value (docs/log-format.md, "Metadata keys"): format id, complete,
/// sample_rate_hz, latitude_deg, hinge axes (finite, non-zero), gyro_full_scale_dps, sensors,
/// duration_s. Throws LogError "<file>:<line>: key 'k': expected ..., got '...'" (no line for keys
/// a program set).
void validate_metadata(const Metadata& meta, std::string_view file);

/// A '# event: ...' line found between rows (a source switch, a gap, a fault).
struct Event {
  double t_s = kNaN;     // time of the row before the event line (NaN before the first row)
  std::string text;      // the text after '# event:'
  std::size_t line = 0;  // 1-based line number in the file
};

/// A time gap between two rows (longer than max(kGapMinS, kGapIntervals / sample_rate_hz)).
struct Gap {
  double t_before_s = kNaN;  // s, the row before the gap
  double length_s = kNaN;    // s, the interval
  std::size_t line = 0;      // line of the row after the gap
};

/// The column names a log with the given optional fields carries, in writing order
/// (kLayoutSingleSensor: the single-sensor form, without gyro2_*, plat2_deg and sensor-2 columns).
std::vector<std::string> column_names(std::uint32_t fields);

/// The column of gyro channel 0..5 (gyro1_x .. gyro2_z), from the same table.
std::string_view gyro_column_name(int channel);

/// Bytes a row of a log with these fields takes, about (the written decimals plus sign, integer
/// digits, point and comma per column); for the free-space check before a run.
double estimated_row_bytes(std::uint32_t fields);

/// Streams samples into a log file. The header says 'complete: false' until finish(true) succeeds,
/// so a crash, Ctrl-C, a full disk or a vanished device never leaves a file that looks whole and is
/// not. The log is written in place (not under a temporary name): a run killed at hour 13 of 14, or
/// a live session, keeps its rows. Rows reach the disk in whole-row chunks.
class LogWriter {
 public:
  /// Opens `path` for writing (throws io::OutputError "<path>: <reason>" on failure; LogError when
  /// `meta` holds an invalid standard value). kLayoutSingleSensor in `fields` writes the
  /// single-sensor form and 'sensors: 1'.
  LogWriter(const std::filesystem::path& path, const Metadata& meta, std::uint32_t fields);
  /// Not finished: closes the file as incomplete; never throws.
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
  /// Throws io::OutputError on a write failure (the file then still says 'complete: false').
  void finish(bool complete, std::string_view reason = {});

  std::uint64_t rows_written() const { return rows_; }
  const std::filesystem::path& path() const { return path_; }

 private:
  void append_row(const Sample& s);
  std::filesystem::path path_;
  io::CheckedFile file_;
  std::vector<std::pair<int, int>> columns_;  // (column table index, decimals) written, in order
  std::int64_t complete_offset_ = -1;         // byte offset of the value of 'complete:' in the header
  std::string buffer_;
  std::uint64_t rows_ = 0;
  bool finished_ = false;
};

/// Every optional column group.
inline constexpr std::uint32_t kAllFieldGroups = kFieldAccel | kFieldTemp | kFieldRefQ | kFieldRefP |
                                                 kFieldTrueBias | kFieldTrueRate | kFieldTruePlat;

/// Reader options.
struct ReaderOptions {
  /// The optional column groups to parse. Columns of other groups are skipped unparsed (read as no
  /// value, their bits absent from fields()): a command parses what it uses, `check` everything.
  std::uint32_t fields = kAllFieldGroups;
  /// Accept a last row cut off mid-line when the log says 'complete: false' (else it is an error).
  bool tolerate_truncated_tail = true;
  /// Accept the single-sensor form ('sensors: 1'); commands that need both gyro triads refuse it
  /// with a message naming the file.
  bool accept_single_sensor = false;
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
  /// kLayoutSingleSensor is set for the single-sensor form.
  std::uint32_t fields() const { return fields_; }
  /// The optional column groups complete in the header, parsed or not (ReaderOptions::fields
  /// chooses which of them fields() holds).
  std::uint32_t header_fields() const { return header_fields_; }
  /// 1 (single-sensor form) or 2.
  int sensors() const { return (fields_ & kLayoutSingleSensor) != 0 ? 1 : 2; }
  const std::vector<std::string>& columns() const { return columns_; }
  /// Index of a column by name (any column, also unknown ones), or -1.
  int column_index(std::string_view name) const;

  /// Reads the next row into `out`. Returns false at the end of the file.
  /// Throws LogError (file:line: what was expected) on a malformed row, a non-increasing t or an
  /// implausible gyro value (beyond kFullScaleMargin x the log's full scale).
  bool next(Sample& out);
  /// Raw value of column `index` in the row last read (NaN when empty or, for an unknown column,
  /// not a number).
  double value(int index) const { return row_[static_cast<std::size_t>(index)]; }

  std::uint64_t rows_read() const { return rows_; }
  const std::vector<Event>& events() const { return events_; }
  /// Time gaps found so far (at most kMaxGapsKept kept; gap_count() counts all).
  const std::vector<Gap>& gaps() const { return gaps_; }
  std::uint64_t gap_count() const { return gap_count_; }
  /// The gap threshold in force, s.
  double gap_threshold_s() const { return gap_threshold_s_; }
  static constexpr std::size_t kMaxGapsKept = 100;
  /// The rate the stamps step at, Hz: from the mean interval between gaps (bursty stamps average
  /// out) and from the median of the first kIntervalsKept intervals (dropped rows do not move it).
  /// NaN with fewer than two rows. Without gap-free intervals (every step a gap: ms stamps under
  /// a rate key) the mean is over all intervals.
  double stamp_rate_mean_hz() const;
  double stamp_rate_median_hz() const;
  static constexpr std::size_t kIntervalsKept = 4096;
  /// True if the file ended in a partial row that was dropped (only for incomplete logs).
  bool dropped_truncated_row() const { return dropped_truncated_; }
  /// Number of rows holding a NaN or empty gyro value (they are returned; callers skip them).
  std::uint64_t rows_with_missing_gyro() const { return missing_gyro_rows_; }
  /// Rows with a gyro value at the stated full scale (|v| >= gyro_full_scale_dps; saturated).
  std::uint64_t rows_saturated() const { return saturated_rows_; }
  /// Channels that repeat their largest |reading| in runs: suspected clipping, stated full scale
  /// or not (estimator/clip_detector.hpp).
  std::vector<est::ClippedChannel> suspected_clipping() const { return clip_.suspected(); }
  /// Gyro channels empty in every row, or stuck at one value (estimator/clip_detector.hpp).
  std::vector<est::DeadChannel> dead_channels() const { return clip_.dead(sensors() == 1 ? 3 : 6); }
  /// The optional column group (SampleField bit) of the column whose value next() refused, once
  /// it has thrown for one; 0 for any other refusal (a required column, a row of the wrong width).
  std::uint32_t refused_group() const { return refused_group_; }
  /// "file:line" for messages.
  std::string where() const;
  const std::filesystem::path& path() const { return path_; }

 private:
  struct Closer {
    void operator()(std::FILE* f) const noexcept { std::fclose(f); }
  };
  struct Pipeline;  // the parse thread and its batches (log_reader.cpp)
  struct Batch;     // rows parsed ahead
  struct Special;   // a line of a batch that is no data row
  bool read_line(std::string_view& line);
  [[noreturn]] void fail(std::string_view what) const;
  void read_header();
  void parse_header_line(std::string_view line);
  void map_columns();
  bool split_row(std::string_view line, double* row, std::string& problem, int& bad_column) const;
  void parse_batch(Batch& b);
  void parse_ahead();
  bool take_special(const Special& sp);
  void check_row(const Sample& s);
  bool platforms_resting(const Sample& s);

  std::filesystem::path path_;
  ReaderOptions opts_;
  std::unique_ptr<std::FILE, Closer> file_;
  // read by the constructor (the header), then by the parse thread only (parse_ahead)
  std::string buf_;
  std::size_t chunk_bytes_ = 0;  // bytes read at a time
  std::size_t buf_pos_ = 0;
  bool eof_ = false;
  bool tail_unterminated_ = false;  // the line read last ended the file without a line end
  std::size_t lines_read_ = 0;
  std::unique_ptr<Pipeline> pipe_;
  // the rows as next() hands them out
  bool last_line_unterminated_ = false;
  bool finished_ = false;
  std::uint32_t refused_group_ = 0;
  std::size_t line_no_ = 0;
  Metadata meta_;
  std::vector<std::string> columns_;
  std::uint32_t fields_ = 0;
  std::uint32_t header_fields_ = 0;
  std::vector<double*> target_;  // column -> value in row_sample_ (nullptr for unknown columns)
  std::vector<char> parse_;      // column -> 0 skip, 1 parse strictly (known), 2 parse leniently (unknown)
  Sample row_sample_;            // the row being read; columns the file lacks stay NaN
  std::vector<double> row_;
  std::vector<Event> events_;
  std::vector<Gap> gaps_;
  std::uint64_t gap_count_ = 0;
  double gap_threshold_s_ = kGapMinS;
  bool rate_stated_ = false;
  double min_dt_s_ = std::numeric_limits<double>::infinity();  // s, shortest interval so far
  double first_t_s_ = kNaN;               // s, the first row's stamp
  double sum_dt_s_ = 0.0;                 // s, the gap-free intervals' sum ...
  std::uint64_t n_dt_ = 0;                // ... and count
  std::vector<double> first_dt_s_;        // s, the first kIntervalsKept intervals
  // per sensor: the plausibility bound and the stated full scale (NaN: none stated, no saturation count)
  std::array<double, 2> gyro_limit_dps_{kFullScaleMargin * kDefaultGyroFullScaleDps,
                                        kFullScaleMargin * kDefaultGyroFullScaleDps};
  std::array<double, 2> full_scale_dps_{kNaN, kNaN};
  std::uint64_t rows_ = 0;
  std::uint64_t missing_gyro_rows_ = 0;
  std::uint64_t saturated_rows_ = 0;
  est::ClipDetector clip_;
  std::array<double, 2> last_plat_deg_{kNaN, kNaN};  // deg, the last row's platform angles
  bool angles_seen_ = false;                         // a row has given both platform angles
  double last_t_ = -std::numeric_limits<double>::infinity();
  bool dropped_truncated_ = false;
};

/// Reads a whole log into memory (for short logs and tests).
std::vector<Sample> read_all(const std::filesystem::path& path, Metadata* meta = nullptr,
                             std::uint32_t* fields = nullptr, ReaderOptions opts = {});

}  // namespace driftless::log
