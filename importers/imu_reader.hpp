// Readers for IMU recordings made by others: delimited text (any separator, optional header),
// EuRoC / TUM-VI imu0/data.csv, NumPy .npy arrays and ROS 1 bags with sensor_msgs/Imu. One
// streaming interface, units converted to the project's (deg/s, m/s^2, s, degC), every assumption
// said in words. Used by `driftless allan --in`, `driftless convert` and compare. Formats, options
// and detection rules: docs/import.md.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "estimator/input_error.hpp"

namespace driftless::importers {

/// A file that cannot be read as asked; the message names the file (and line or message) and what
/// was expected. The house's one input-error type (driftless::InputError), so the CLI reports it
/// like every other bad input; the message carries its own location.
class ImportError : public InputError {
 public:
  explicit ImportError(const std::string& message) : InputError("", 0, "", message) {}
};

/// The input formats (`--format`).
enum class Format { kAuto, kText, kEuroc, kNpy, kBag, kDriftlessLog };
const char* to_string(Format f);
/// Parses "auto", "text", "euroc", "npy", "bag", "log"; throws ImportError listing the names.
Format parse_format(const std::string& s);

/// What a channel measures, and so its unit after import.
enum class Quantity {
  kRate,         // deg/s
  kAccel,        // m/s^2
  kTemperature,  // degC
};
const char* unit_of(Quantity q);

/// One imported channel.
struct ChannelInfo {
  std::string name;    // the source's name (header column, bag field) or "col<N>"
  Quantity quantity = Quantity::kRate;
  int axis = -1;       // 0, 1, 2 for x, y, z of a triad; -1 otherwise
};

/// What a reader found and assumed.
struct StreamInfo {
  std::string source;                     // the file
  Format format = Format::kText;          // the format read (after detection)
  std::vector<ChannelInfo> channels;
  bool has_time = false;                  // rows carry a timestamp (s)
  std::int64_t epoch_s = 0;               // s, whole: the first stamp floored; ImuBlock::t_s counts from it
                                          // (the difference formed in integers, so ns epoch stamps keep ns)
  double nominal_rate_hz = 0.0;           // Hz, from the file's own metadata (0: none)
  std::uint64_t rows_estimate = 0;        // rows to expect: exact for .npy and bags, from the size and
                                          // the first lines for text (0: unknown); for reserving memory
  std::vector<std::string> assumptions;   // what was detected or assumed, one sentence each
};

/// A block of rows, channel-major: values[c][r]; t_s[r] in s since StreamInfo::epoch_s (NaN when no
/// time); loc[r] the source
/// line (text) or message number (bag), 1-based, for messages.
/// A caller that wants only the values of a record without time sets `bare_untimed` before read():
/// the text and .npy readers then leave t_s and loc empty when the source has no time (16 bytes a
/// row not written), and rows() counts the values.
struct ImuBlock {
  std::vector<double> t_s;
  std::vector<std::vector<double>> values;
  std::vector<std::uint64_t> loc;
  bool bare_untimed = false;
  std::size_t rows() const { return t_s.empty() && !values.empty() ? values.front().size() : t_s.size(); }
  /// True when this read leaves t_s and loc empty (set, no time, and at least one channel).
  bool bare(bool has_time) const { return bare_untimed && !has_time && !values.empty(); }
  void clear();
};

/// A streaming reader.
class ImuReader {
 public:
  virtual ~ImuReader() = default;
  const StreamInfo& info() const { return info_; }
  /// Reads up to max_rows rows into `out` (cleared first). Returns false when nothing is left.
  /// A missing value (empty field, "nan") is NaN; a malformed row throws ImportError (file:line).
  virtual bool read(ImuBlock& out, std::size_t max_rows) = 0;
  /// "file:line" (or "file: message N") for a location of this source.
  virtual std::string where(std::uint64_t loc) const;
  /// Puts a sentence first in info().assumptions (how the format was chosen).
  void say_first(std::string s) { info_.assumptions.insert(info_.assumptions.begin(), std::move(s)); }

 protected:
  StreamInfo info_;
};

/// Options shared by every reader (`driftless allan --in`, `convert`). Empty strings mean "detect".
struct ImportOptions {
  Format format = Format::kAuto;
  std::vector<std::string> columns;        // rate channels: header names or 1-based indices
  std::vector<std::string> accel_columns;  // accelerometer channels (x, y, z)
  std::string time_column;                 // name or 1-based index; "none": rows carry no time
  std::string temp_column;                 // name or 1-based index
  std::string units;                       // rate: deg/s, rad/s, lsb:<LSB per deg/s>
  std::string accel_units;                 // m/s^2, g, lsb:<LSB per g>
  std::string time_units;                  // s, ms, us, ns
  std::string separator;                   // ",", ";", "tab", "space", "|" or any one character
  std::string topic;                       // bag: the sensor_msgs/Imu topic
  bool no_header = false;                  // text: the first row is data
  bool all_columns = false;                // npy/text without names: every column is a rate channel
};

/// Opens `path`: detects the format (unless given), the layout, the units and the time base, and
/// says what it assumed in info().assumptions. Throws ImportError with the file and the cause.
std::unique_ptr<ImuReader> open_imu(const std::filesystem::path& path, const ImportOptions& opt);

/// Which format `path` holds, from its first bytes (and name); `why` says what decided it.
Format detect_format(const std::filesystem::path& path, std::string* why = nullptr);

/// True when this build can read ROS bags (librosbag-dev was found at configure time).
bool bag_support();

}  // namespace driftless::importers
