#include "estimator/log.hpp"

#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <sstream>
#include <system_error>

namespace driftless::log {
namespace {

// the column table: name, the optional group it belongs to (0 = required), decimals written
struct ColumnSpec {
  const char* name;
  std::uint32_t field;
  int decimals;
};

constexpr std::array<ColumnSpec, 40> kColumns = {{
    {"t", 0, 6},
    {"gyro1_x", 0, 7}, {"gyro1_y", 0, 7}, {"gyro1_z", 0, 7},
    {"gyro2_x", 0, 7}, {"gyro2_y", 0, 7}, {"gyro2_z", 0, 7},
    {"plat1_deg", 0, 6}, {"plat2_deg", 0, 6},
    {"ref_qw", kFieldRefQ, 10}, {"ref_qx", kFieldRefQ, 10},
    {"ref_qy", kFieldRefQ, 10}, {"ref_qz", kFieldRefQ, 10},
    {"ref_px", kFieldRefP, 4}, {"ref_py", kFieldRefP, 4}, {"ref_pz", kFieldRefP, 4},
    {"accel1_x", kFieldAccel, 5}, {"accel1_y", kFieldAccel, 5}, {"accel1_z", kFieldAccel, 5},
    {"accel2_x", kFieldAccel, 5}, {"accel2_y", kFieldAccel, 5}, {"accel2_z", kFieldAccel, 5},
    {"temp1", kFieldTemp, 3}, {"temp2", kFieldTemp, 3},
    {"true_bias1_x", kFieldTrueBias, 9}, {"true_bias1_y", kFieldTrueBias, 9},
    {"true_bias1_z", kFieldTrueBias, 9}, {"true_bias2_x", kFieldTrueBias, 9},
    {"true_bias2_y", kFieldTrueBias, 9}, {"true_bias2_z", kFieldTrueBias, 9},
    {"true_rate_x", kFieldTrueRate, 9}, {"true_rate_y", kFieldTrueRate, 9},
    {"true_rate_z", kFieldTrueRate, 9},
    {"true_plat1_deg", kFieldTruePlat, 6}, {"true_plat2_deg", kFieldTruePlat, 6},
    // spare slots keep the table size fixed; unnamed entries are skipped
    {nullptr, 0, 0}, {nullptr, 0, 0}, {nullptr, 0, 0}, {nullptr, 0, 0}, {nullptr, 0, 0},
}};

constexpr std::uint32_t kAllFields = kFieldAccel | kFieldTemp | kFieldRefQ | kFieldRefP |
                                     kFieldTrueBias | kFieldTrueRate | kFieldTruePlat;

// where column slot i lives inside a Sample
double& slot(Sample& s, std::size_t i) {
  switch (i) {
    case 0: return s.t_s;
    case 1: case 2: case 3: return s.gyro1_dps[static_cast<Eigen::Index>(i - 1)];
    case 4: case 5: case 6: return s.gyro2_dps[static_cast<Eigen::Index>(i - 4)];
    case 7: return s.plat1_deg;
    case 8: return s.plat2_deg;
    case 9: case 10: case 11: case 12: return s.ref_q_wxyz[static_cast<Eigen::Index>(i - 9)];
    case 13: case 14: case 15: return s.ref_p_enu_m[static_cast<Eigen::Index>(i - 13)];
    case 16: case 17: case 18: return s.accel1_mps2[static_cast<Eigen::Index>(i - 16)];
    case 19: case 20: case 21: return s.accel2_mps2[static_cast<Eigen::Index>(i - 19)];
    case 22: return s.temp1_c;
    case 23: return s.temp2_c;
    case 24: case 25: case 26: return s.true_bias1_dps[static_cast<Eigen::Index>(i - 24)];
    case 27: case 28: case 29: return s.true_bias2_dps[static_cast<Eigen::Index>(i - 27)];
    case 30: case 31: case 32: return s.true_rate_body_dps[static_cast<Eigen::Index>(i - 30)];
    case 33: return s.true_plat1_deg;
    case 34: return s.true_plat2_deg;
    default: break;
  }
  throw std::logic_error("log: column slot out of range");
}

double slot_value(const Sample& s, std::size_t i) { return slot(const_cast<Sample&>(s), i); }

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

// parses a whole field as a double; empty or "nan" -> NaN. Returns false on junk.
bool parse_number(std::string_view field, double& out) {
  field = trim(field);
  if (field.empty()) {
    out = kNaN;
    return true;
  }
  const char* first = field.data();
  const char* last = field.data() + field.size();
  if (*first == '+') ++first;
  auto [ptr, ec] = std::from_chars(first, last, out);
  return ec == std::errc() && ptr == last;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// metadata

void Metadata::set(std::string key, std::string value) {
  for (auto& [k, v] : entries_) {
    if (k == key) {
      v = std::move(value);
      return;
    }
  }
  entries_.emplace_back(std::move(key), std::move(value));
}

std::optional<std::string> Metadata::get(std::string_view key) const {
  for (const auto& [k, v] : entries_) {
    if (k == key) return v;
  }
  return std::nullopt;
}

double Metadata::get_number(std::string_view key, double fallback, std::string_view where) const {
  auto v = get(key);
  if (!v) return fallback;
  double out = kNaN;
  if (!parse_number(*v, out) || v->empty()) {
    throw LogError(std::string(where.empty() ? "log metadata" : where), 0, std::string(key),
                   "expected a number, got '" + *v + "'");
  }
  return out;
}

Eigen::Vector3d Metadata::get_vector3(std::string_view key, const Eigen::Vector3d& fallback,
                                      std::string_view where) const {
  auto v = get(key);
  if (!v) return fallback;
  std::istringstream in(*v);
  Eigen::Vector3d out;
  std::string extra;
  if (!(in >> out[0] >> out[1] >> out[2]) || (in >> extra)) {
    throw LogError(std::string(where.empty() ? "log metadata" : where), 0, std::string(key),
                   "expected three numbers 'x y z', got '" + *v + "'");
  }
  return out;
}

bool Metadata::complete() const {
  auto v = get("complete");
  return !v || trim(*v) == "true";
}

std::vector<std::string> column_names(std::uint32_t fields) {
  std::vector<std::string> names;
  for (const auto& c : kColumns) {
    if (c.name != nullptr && (c.field == 0 || (fields & c.field) != 0)) names.emplace_back(c.name);
  }
  return names;
}

// ---------------------------------------------------------------------------------------------
// writer

LogWriter::LogWriter(const std::filesystem::path& path, const Metadata& meta, std::uint32_t fields)
    : path_(path), fields_(fields & kAllFields) {
  file_ = std::fopen(path.c_str(), "wb");
  if (file_ == nullptr) {
    throw std::runtime_error(path.string() + ": cannot open for writing: " + std::strerror(errno));
  }
  // metadata: format first, 'complete' second (patched in place on a clean finish)
  std::string head = "# format: " + std::string(kFormatId) + "\n";
  head += "# complete: ";
  complete_offset_ = static_cast<long>(head.size());
  head += "false\n";
  for (const auto& [k, v] : meta.entries()) {
    if (k == "format" || k == "complete") continue;
    head += "# " + k + ": " + v + "\n";
  }
  const auto names = column_names(fields_);
  for (std::size_t i = 0; i < names.size(); ++i) {
    head += (i ? "," : "") + names[i];
  }
  head += "\n";
  buffer_.reserve(1 << 20);
  buffer_ = head;
  flush();
}

LogWriter::~LogWriter() {
  if (!finished_ && file_ != nullptr) {
    try {
      finish(false, "writer closed before the run finished");
    } catch (...) {
      // destructor must not throw; the header already says complete: false
    }
  }
}

void LogWriter::append_row(const Sample& s) {
  char tmp[64];
  bool first = true;
  for (std::size_t i = 0; i < kColumns.size(); ++i) {
    const auto& c = kColumns[i];
    if (c.name == nullptr || (c.field != 0 && (fields_ & c.field) == 0)) continue;
    if (!first) buffer_.push_back(',');
    first = false;
    const double v = slot_value(s, i);
    if (std::isnan(v)) continue;  // empty field
    auto [ptr, ec] = std::to_chars(tmp, tmp + sizeof tmp, v, std::chars_format::fixed, c.decimals);
    if (ec != std::errc()) {
      ptr = std::to_chars(tmp, tmp + sizeof tmp, v).ptr;  // huge values: shortest form
    }
    buffer_.append(tmp, ptr);
  }
  buffer_.push_back('\n');
}

void LogWriter::write(const Sample& s) {
  append_row(s);
  ++rows_;
  if (buffer_.size() >= (1u << 20) - 4096) flush();
}

void LogWriter::event(double t_s, std::string_view text) {
  char tmp[64];
  auto ptr = std::to_chars(tmp, tmp + sizeof tmp, t_s, std::chars_format::fixed, 6).ptr;
  buffer_ += "# event: t=";
  buffer_.append(tmp, ptr);
  buffer_ += " ";
  for (char c : text) buffer_.push_back(c == '\n' ? ' ' : c);
  buffer_ += "\n";
}

void LogWriter::flush() {
  if (file_ == nullptr || buffer_.empty()) return;
  if (std::fwrite(buffer_.data(), 1, buffer_.size(), file_) != buffer_.size() ||
      std::fflush(file_) != 0) {
    throw std::runtime_error(path_.string() + ": write failed: " + std::strerror(errno));
  }
  buffer_.clear();
}

void LogWriter::finish(bool complete, std::string_view reason) {
  if (finished_) return;
  finished_ = true;
  if (!complete) {
    buffer_ += "# incomplete: ";
    buffer_ += reason.empty() ? std::string_view("run did not finish") : reason;
    buffer_ += "\n";
  }
  flush();
  if (complete) {
    // 'false' -> 'true ' keeps the byte length, so the rows do not move
    if (std::fseek(file_, complete_offset_, SEEK_SET) != 0 || std::fputs("true ", file_) < 0 ||
        std::fflush(file_) != 0) {
      std::fclose(file_);
      file_ = nullptr;
      throw std::runtime_error(path_.string() + ": cannot mark the log complete: " +
                               std::strerror(errno));
    }
  }
  if (std::fclose(file_) != 0) {
    file_ = nullptr;
    throw std::runtime_error(path_.string() + ": close failed: " + std::strerror(errno));
  }
  file_ = nullptr;
}

// ---------------------------------------------------------------------------------------------
// reader

LogReader::LogReader(const std::filesystem::path& path, ReaderOptions opts)
    : path_(path), opts_(opts) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) {
    throw LogError(path.string(), 0, "", "no such file");
  }
  if (std::filesystem::is_directory(path, ec)) {
    throw LogError(path.string(), 0, "", "is a directory, expected a driftless log (CSV)");
  }
  file_ = std::fopen(path.c_str(), "rb");
  if (file_ == nullptr) {
    throw LogError(path.string(), 0, "", std::string("cannot open: ") + std::strerror(errno));
  }
  buf_.reserve(1 << 20);

  // metadata lines, then the header row
  std::string_view line;
  bool saw_any = false;
  while (read_line(line)) {
    saw_any = true;
    std::string_view t = trim(line);
    if (t.empty()) continue;
    if (t.front() == '#') {
      parse_header_line(t);
      continue;
    }
    // the header row
    std::size_t start = 0;
    while (start <= t.size()) {
      std::size_t comma = t.find(',', start);
      if (comma == std::string_view::npos) comma = t.size();
      columns_.emplace_back(trim(t.substr(start, comma - start)));
      start = comma + 1;
    }
    break;
  }
  if (!saw_any) {
    std::fclose(file_);
    file_ = nullptr;
    throw LogError(path.string(), 0, "",
                   "empty file; expected '# format: driftless-log 1' metadata and a header row (see "
                   "docs/log-format.md)");
  }
  if (columns_.empty()) {
    fail("no header row; expected a CSV header naming the columns (t, gyro1_x, ...)");
  }
  if (auto fmt = meta_.get("format"); fmt && trim(*fmt) != kFormatId) {
    fail("unsupported format '" + *fmt + "'; this reader understands '" + std::string(kFormatId) +
         "'");
  }
  // map columns to sample slots
  slot_of_column_.assign(columns_.size(), -1);
  std::vector<bool> seen(kColumns.size(), false);
  for (std::size_t c = 0; c < columns_.size(); ++c) {
    for (std::size_t k = 0; k < kColumns.size(); ++k) {
      if (kColumns[k].name != nullptr && columns_[c] == kColumns[k].name) {
        if (seen[k]) fail("column '" + columns_[c] + "' appears twice in the header");
        seen[k] = true;
        slot_of_column_[c] = static_cast<int>(k);
      }
    }
  }
  std::string missing;
  for (std::size_t k = 0; k < kColumns.size(); ++k) {
    if (kColumns[k].name != nullptr && kColumns[k].field == 0 && !seen[k]) {
      missing += (missing.empty() ? "" : ", ") + std::string(kColumns[k].name);
    }
  }
  if (!missing.empty()) {
    fail("header lacks required column(s) " + missing +
         " (required: t, gyro1_x..gyro2_z, plat1_deg, plat2_deg; see docs/log-format.md)");
  }
  // an optional group counts only when all its columns are there
  for (std::uint32_t bit = 1; bit <= kFieldTruePlat; bit <<= 1) {
    bool all = true;
    for (std::size_t k = 0; k < kColumns.size(); ++k) {
      if (kColumns[k].field == bit && !seen[k]) all = false;
    }
    if (all) fields_ |= bit;
  }
  row_.assign(columns_.size(), kNaN);
}

LogReader::~LogReader() {
  if (file_ != nullptr) std::fclose(file_);
}

std::string LogReader::where() const { return path_.string() + ":" + std::to_string(line_no_); }

void LogReader::fail(std::string_view what) const {
  throw LogError(path_.string(), line_no_, "", std::string(what));
}

int LogReader::column_index(std::string_view name) const {
  for (std::size_t i = 0; i < columns_.size(); ++i) {
    if (columns_[i] == name) return static_cast<int>(i);
  }
  return -1;
}

void LogReader::parse_header_line(std::string_view line) {
  line.remove_prefix(1);  // '#'
  const auto colon = line.find(':');
  if (colon == std::string_view::npos) return;  // a plain comment
  const std::string_view key = trim(line.substr(0, colon));
  const std::string_view value = trim(line.substr(colon + 1));
  if (key.empty() || key.find(' ') != std::string_view::npos) return;  // prose, not metadata
  if (key == "event") {
    events_.push_back(Event{rows_ ? last_t_ : kNaN, std::string(value), line_no_});
  } else if (key == "incomplete") {
    meta_.set("incomplete_reason", std::string(value));
  } else if (rows_ == 0) {
    meta_.set(std::string(key), std::string(value));
  }
}

bool LogReader::read_line(std::string_view& line) {
  for (;;) {
    const std::size_t nl = buf_.find('\n', buf_pos_);
    if (nl != std::string::npos) {
      line = std::string_view(buf_).substr(buf_pos_, nl - buf_pos_);
      buf_pos_ = nl + 1;
      ++line_no_;
      return true;
    }
    if (eof_) {
      if (buf_pos_ < buf_.size()) {
        line = std::string_view(buf_).substr(buf_pos_);
        buf_pos_ = buf_.size();
        ++line_no_;
        last_line_unterminated_ = true;
        return true;
      }
      return false;
    }
    // refill: keep the unread tail, append a new chunk
    buf_.erase(0, buf_pos_);
    buf_pos_ = 0;
    const std::size_t old = buf_.size();
    buf_.resize(old + (1 << 20));
    const std::size_t got = std::fread(buf_.data() + old, 1, 1 << 20, file_);
    buf_.resize(old + got);
    if (got == 0) {
      if (std::ferror(file_)) fail(std::string("read error: ") + std::strerror(errno));
      eof_ = true;
    }
  }
}

bool LogReader::next(Sample& out) {
  std::string_view line;
  for (;;) {
    if (!read_line(line)) return false;
    std::string_view t = trim(line);
    if (t.empty()) continue;
    if (t.front() == '#') {
      parse_header_line(t);
      continue;
    }
    break;
  }
  // split and parse; an unterminated last line of an incomplete log may be cut short
  const bool may_be_cut = last_line_unterminated_ && !meta_.complete();
  std::size_t col = 0;
  std::size_t start = 0;
  bool ok = true;
  std::string problem;
  while (start <= line.size()) {
    std::size_t comma = line.find(',', start);
    if (comma == std::string_view::npos) comma = line.size();
    if (col >= columns_.size()) {
      ok = false;
      problem = "expected " + std::to_string(columns_.size()) + " fields as in the header, got more";
      break;
    }
    const std::string_view field = line.substr(start, comma - start);
    if (!parse_number(field, row_[col])) {
      ok = false;
      problem = "column '" + columns_[col] + "': expected a number, got '" + std::string(field) + "'";
      break;
    }
    ++col;
    start = comma + 1;
  }
  if (ok && col != columns_.size()) {
    ok = false;
    problem = "expected " + std::to_string(columns_.size()) + " fields as in the header, got " +
              std::to_string(col);
  }
  // the writer ends every row with a newline: an unterminated last line of an incomplete log
  // was cut mid-write, even when what is left happens to parse
  if (may_be_cut && opts_.tolerate_truncated_tail) {
    dropped_truncated_ = true;
    return false;
  }
  if (!ok) fail(problem);
  out = Sample{};
  for (std::size_t c = 0; c < columns_.size(); ++c) {
    const int s = slot_of_column_[c];
    if (s >= 0) slot(out, static_cast<std::size_t>(s)) = row_[c];
  }
  if (!std::isfinite(out.t_s)) fail("column 't': expected a time in seconds, got an empty or NaN value");
  if (!(out.t_s > last_t_)) {
    char msg[160];
    std::snprintf(msg, sizeof msg, "t = %.6f s is not greater than the previous t = %.6f s "
                  "(time must increase strictly)", out.t_s, last_t_);
    fail(msg);
  }
  last_t_ = out.t_s;
  if (!out.gyros_finite()) ++missing_gyro_rows_;
  ++rows_;
  return true;
}

std::vector<Sample> read_all(const std::filesystem::path& path, Metadata* meta,
                             std::uint32_t* fields) {
  LogReader reader(path);
  std::vector<Sample> out;
  Sample s;
  while (reader.next(s)) out.push_back(s);
  if (meta != nullptr) *meta = reader.metadata();
  if (fields != nullptr) *fields = reader.fields();
  return out;
}

}  // namespace driftless::log
