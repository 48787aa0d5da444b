// The log reader: metadata and header, then rows, each checked as it is read (docs/log-format.md,
// "Validation"). Every command that reads a log goes through here.
#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <exception>
#include <mutex>
#include <system_error>
#include <thread>

#include "estimator/fixed_decimal.hpp"
#include "estimator/log.hpp"
#include "estimator/log_columns.hpp"

namespace driftless::log {
namespace {

constexpr std::size_t kChunkBytes = 1u << 20;
constexpr std::string_view kUtf8Bom = "\xEF\xBB\xBF";

// rows a batch of the parse thread holds, and batches parsed ahead at most (constant memory:
// 4 x 4096 rows of 35 columns, 4.6 MB)
constexpr std::size_t kBatchRows = 4096;
constexpr std::size_t kBatchesAhead = 4;

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

// parses a whole field as a double; empty or "nan" -> NaN. Returns false on junk.
bool parse_field(const char* first, const char* last, double& out) {
  while (first != last && (*first == ' ' || *first == '\t')) ++first;
  while (last != first && (last[-1] == ' ' || last[-1] == '\t' || last[-1] == '\r')) --last;
  if (first == last) {
    out = kNaN;
    return true;
  }
  return io::parse_decimal(first, last, out) == last;
}

std::string number_text(double v) {
  char buf[64];
  auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  return ec == std::errc() ? std::string(buf, end) : std::string("?");
}

// a time as the log writes it (6 decimals), or the shortest form for absurd values
std::string time_text(double t_s) {
  if (!(std::fabs(t_s) < 1e15)) return number_text(t_s);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6f", t_s);
  return buf;
}

}  // namespace

// The parse thread: reading the file, cutting it into lines and the lines into numbers (most of a
// read's time) run beside the caller, which takes the rows in order and checks them (check_row:
// time, gaps, plausibility, clipping) as before. Lines that are no data row (comments, metadata,
// events, a malformed row, the file's unterminated end, a read error) travel in the batch at their
// place among the rows, and next() meets them where the serial reader did: the same rows, the same
// errors at the same file:line.
struct LogReader::Special {
  enum class Kind { kComment, kProblem, kUnterminated, kError };
  std::size_t before_row = 0;  // the batch's row it comes before
  Kind kind = Kind::kComment;
  std::string text;            // the comment line, or the malformed row's problem
  std::size_t line = 0;
  bool unterminated = false;   // the line had no line end (the file's last)
  int column = -1;             // kProblem: the column whose value is no number (-1: the row's width)
  std::exception_ptr error;    // kError: what reading threw
};

struct LogReader::Batch {
  std::vector<double> values;       // rows x columns, as row_
  std::vector<std::size_t> lines;   // each row's line in the file
  std::vector<Special> specials;
  bool end = false;                 // nothing follows this batch
  std::size_t rows() const { return lines.size(); }
  void clear() {
    values.clear();
    lines.clear();
    specials.clear();
    end = false;
  }
};

// A stream (a FIFO, a terminal) is parsed on the caller's thread, a batch at a time: a thread
// blocked reading a stream that stays open could not be stopped when the reader goes away
struct LogReader::Pipeline {
  bool threaded = false;
  std::mutex m;
  std::condition_variable cv;
  std::deque<Batch> ready;
  std::vector<Batch> spare;  // batches handed back, their storage reused
  bool stop = false;
  std::thread worker;
  Batch cur;                 // the batch next() reads, and where in it
  std::size_t row = 0, special = 0;

  Batch take_spare() {
    std::lock_guard<std::mutex> lk(m);
    if (spare.empty()) return Batch{};
    Batch b = std::move(spare.back());
    spare.pop_back();
    b.clear();
    return b;
  }
  // false when the reader is going away
  bool push(Batch&& b) {
    std::unique_lock<std::mutex> lk(m);
    cv.wait(lk, [&] { return stop || ready.size() < kBatchesAhead; });
    if (stop) return false;
    ready.push_back(std::move(b));
    cv.notify_all();
    return true;
  }
  // the next batch into cur (the old one's storage goes back)
  void advance() {
    std::unique_lock<std::mutex> lk(m);
    spare.push_back(std::move(cur));
    cv.wait(lk, [&] { return !ready.empty(); });
    cur = std::move(ready.front());
    ready.pop_front();
    row = special = 0;
    cv.notify_all();
  }
  void halt() {
    {
      std::lock_guard<std::mutex> lk(m);
      stop = true;
    }
    cv.notify_all();
    if (worker.joinable()) worker.join();
  }
};

LogReader::LogReader(const std::filesystem::path& path, ReaderOptions opts) : path_(path), opts_(opts) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw LogError(path.string(), 0, "", "no such file");
  if (std::filesystem::is_directory(path, ec)) {
    throw LogError(path.string(), 0, "", "is a directory, expected a driftless log (CSV)");
  }
  errno = 0;
  file_.reset(std::fopen(path.c_str(), "rb"));
  if (!file_) throw LogError(path.string(), 0, "", std::string("cannot open: ") + std::strerror(errno));
  // chunks of 1 MiB, or the whole file when it is smaller
  const auto size = std::filesystem::file_size(path, ec);
  chunk_bytes_ = ec ? kChunkBytes : static_cast<std::size_t>(std::min<std::uintmax_t>(kChunkBytes, size + 1));
  buf_.reserve(chunk_bytes_);
  read_header();
  map_columns();
  validate_metadata(meta_, path_.string());
  if (sensors() == 1 && !opts_.accept_single_sensor) {
    throw LogError(path_.string(), meta_.line_of("sensors"), "sensors",
                   "a single-sensor log ('sensors: 1'); this command needs both gyro triads "
                   "(gyro1_*, gyro2_*; docs/log-format.md)");
  }
  const double rate = meta_.sample_rate_hz();
  rate_stated_ = std::isfinite(rate);
  gap_threshold_s_ = rate_stated_ ? driftless::gap_threshold_s(1.0 / rate) : kGapMinS;
  for (int sensor = 1; sensor <= 2; ++sensor) {
    const std::size_t i = static_cast<std::size_t>(sensor - 1);
    gyro_limit_dps_[i] = kFullScaleMargin * meta_.gyro_full_scale_dps(sensor);
    if (!meta_.gyro_full_scale_key(sensor).empty()) full_scale_dps_[i] = meta_.gyro_full_scale_dps(sensor);
  }
  pipe_ = std::make_unique<Pipeline>();
  pipe_->threaded = std::filesystem::is_regular_file(path, ec);
  if (pipe_->threaded) pipe_->worker = std::thread([this] { parse_ahead(); });
}

LogReader::~LogReader() {
  if (pipe_) pipe_->halt();
}

std::string LogReader::where() const { return path_.string() + ":" + std::to_string(line_no_); }

void LogReader::fail(std::string_view what) const { throw LogError(path_.string(), line_no_, "", std::string(what)); }

int LogReader::column_index(std::string_view name) const {
  for (std::size_t i = 0; i < columns_.size(); ++i) {
    if (columns_[i] == name) return static_cast<int>(i);
  }
  return -1;
}

// metadata lines, then the header row
void LogReader::read_header() {
  std::string_view line;
  bool saw_any = false;
  while (read_line(line)) {
    line_no_ = lines_read_;
    if (line_no_ == 1 && line.substr(0, kUtf8Bom.size()) == kUtf8Bom) line.remove_prefix(kUtf8Bom.size());
    saw_any = true;
    const std::string_view t = trim(line);
    if (t.empty()) continue;
    if (t.front() == '#') {
      parse_header_line(t);
      continue;
    }
    std::size_t start = 0;
    while (start <= t.size()) {
      std::size_t comma = t.find(',', start);
      if (comma == std::string_view::npos) comma = t.size();
      columns_.emplace_back(trim(t.substr(start, comma - start)));
      start = comma + 1;
    }
    return;
  }
  if (!saw_any) {
    throw LogError(path_.string(), 0, "", "empty file; expected '# format: driftless-log 1' metadata "
                   "and a header row (see docs/log-format.md)");
  }
  fail("no header row; expected a CSV header naming the columns (t, gyro1_x, ...)");
}

// columns -> places in a Sample; the required ones must be there, unknown ones are kept as values
void LogReader::map_columns() {
  const bool single = meta_.sensors() == 1;
  target_.assign(columns_.size(), nullptr);
  parse_.assign(columns_.size(), 2);
  std::vector<bool> seen(detail::kColumns.size(), false);
  for (std::size_t c = 0; c < columns_.size(); ++c) {
    for (std::size_t k = 0; k < detail::kColumns.size(); ++k) {
      if (columns_[c] != detail::kColumns[k].name) continue;
      if (seen[k]) fail("column '" + columns_[c] + "' appears twice in the header");
      if (single && detail::kColumns[k].sensor == 2) {
        fail("column '" + columns_[c] + "' in a single-sensor log ('sensors: 1' has no sensor-2 columns)");
      }
      seen[k] = true;
      const std::uint32_t group = detail::kColumns[k].field;
      const bool wanted = group == 0 || (opts_.fields & group) != 0;
      parse_[c] = wanted ? 1 : 0;
      if (wanted) target_[c] = &detail::column_slot(row_sample_, k);
    }
  }
  std::string missing;
  for (std::size_t k = 0; k < detail::kColumns.size(); ++k) {
    if (detail::column_required(k, single) && !seen[k]) {
      missing += (missing.empty() ? "" : ", ") + std::string(detail::kColumns[k].name);
    }
  }
  if (!missing.empty()) {
    fail("header lacks required column(s) " + missing +
         (single ? " (required in the single-sensor form: t, gyro1_x..gyro1_z"
                 : " (required: t, gyro1_x..gyro2_z, plat1_deg, plat2_deg") +
         "; see docs/log-format.md)" +
         (meta_.has("format") ? std::string()
                              : std::string("; the file has no '# format: driftless-log 1' line: a recording from "
                                            "another tool? a single IMU's: make a log of it with 'driftless convert "
                                            "--in FILE --out LOG.csv' (docs/import.md); a dual-gyro box's: rename "
                                            "its columns to t, gyro1_x..gyro2_z (deg/s), plat1_deg, plat2_deg (deg) "
                                            "and add that line (docs/log-format.md)")));
  }
  if (single) {
    fields_ |= kLayoutSingleSensor;
    if (!seen[detail::kPlat1Column]) row_sample_.plat1_deg = 0.0;  // the sensor is fixed to the box
  }
  // an optional group counts only when all its columns (of the sensors present) are there
  for (std::uint32_t bit = 1; bit <= kFieldTruePlat; bit <<= 1) {
    bool all = true;
    for (std::size_t k = 0; k < detail::kColumns.size(); ++k) {
      if (detail::kColumns[k].field == bit && !seen[k] && !(single && detail::kColumns[k].sensor == 2)) all = false;
    }
    if (all) header_fields_ |= bit;
    if (all && (opts_.fields & bit) != 0) fields_ |= bit;
  }
  row_.assign(columns_.size(), kNaN);
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
    meta_.set("incomplete_reason", std::string(value), line_no_);
  } else if (rows_ == 0) {
    if (const std::size_t first = meta_.line_of(key); meta_.has(key)) {
      fail("metadata key '" + std::string(key) + "' repeats line " + std::to_string(first) +
           " (each key once; see docs/log-format.md)");
    }
    meta_.set(std::string(key), std::string(value), line_no_);
  }
}

bool LogReader::read_line(std::string_view& line) {
  for (;;) {
    const std::size_t nl = buf_.find('\n', buf_pos_);
    if (nl != std::string::npos) {
      line = std::string_view(buf_).substr(buf_pos_, nl - buf_pos_);
      buf_pos_ = nl + 1;
      ++lines_read_;
      return true;
    }
    if (eof_) {
      if (buf_pos_ < buf_.size()) {
        line = std::string_view(buf_).substr(buf_pos_);
        buf_pos_ = buf_.size();
        ++lines_read_;
        tail_unterminated_ = true;
        return true;
      }
      return false;
    }
    // refill: keep the unread tail, append a new chunk
    buf_.erase(0, buf_pos_);
    buf_pos_ = 0;
    const std::size_t old = buf_.size();
    buf_.resize(old + chunk_bytes_);
    errno = 0;
    const std::size_t got = std::fread(buf_.data() + old, 1, chunk_bytes_, file_.get());
    buf_.resize(old + got);
    if (got == 0) {
      if (std::ferror(file_.get())) {
        throw LogError(path_.string(), lines_read_ + 1, "", std::string("read error: ") + std::strerror(errno));
      }
      eof_ = true;
    }
  }
}

// splits a row into `row` (every column, as row_); false with `problem` set on a malformed row.
// Reads only what the constructor set (columns_, parse_): the parse thread calls it
bool LogReader::split_row(std::string_view line, double* row, std::string& problem, int& bad_column) const {
  const char* p = line.data();
  const char* const end = line.data() + line.size();
  std::size_t col = 0;
  for (;;) {
    if (col < columns_.size() && parse_[col] == 0) {
      // a column the caller does not use: skipped unparsed
      const char* comma = static_cast<const char*>(std::memchr(p, ',', static_cast<std::size_t>(end - p)));
      ++col;
      if (comma == nullptr) break;
      p = comma + 1;
      continue;
    }
    if (col < columns_.size()) {
      // the common case: a plain number right up to the comma
      const char* q = io::parse_decimal(p, end, row[col]);
      if (q != nullptr && q != end && *q == ',') {
        ++col;
        p = q + 1;
        continue;
      }
    }
    const char* comma = static_cast<const char*>(std::memchr(p, ',', static_cast<std::size_t>(end - p)));
    const char* field_end = comma != nullptr ? comma : end;
    if (col >= columns_.size()) {
      problem = "expected " + std::to_string(columns_.size()) + " fields as in the header, got more";
      return false;
    }
    if (!parse_field(p, field_end, row[col])) {
      if (parse_[col] == 1) {
        problem = "column '" + columns_[col] + "': expected a number, got '" + std::string(p, field_end) + "'";
        bad_column = static_cast<int>(col);
        return false;
      }
      row[col] = kNaN;  // an unknown column may hold text: ignored
    }
    ++col;
    if (comma == nullptr) break;
    p = comma + 1;
  }
  if (col != columns_.size()) {
    problem = "expected " + std::to_string(columns_.size()) + " fields as in the header, got " + std::to_string(col);
    return false;
  }
  return true;
}

// the per-row checks: time, gaps, gyro plausibility against the full scale
// both platforms at rest in this row: their angles read and unchanged since the last row. A log
// that has given no angle yet (no angle columns, an end-stop box) does not say: taken as resting
bool LogReader::platforms_resting(const Sample& s) {
  const bool read = std::isfinite(s.plat1_deg) && std::isfinite(s.plat2_deg);
  const bool resting = read ? s.plat1_deg == last_plat_deg_[0] && s.plat2_deg == last_plat_deg_[1] : !angles_seen_;
  angles_seen_ = angles_seen_ || read;
  last_plat_deg_ = {s.plat1_deg, s.plat2_deg};
  return resting;
}

void LogReader::check_row(const Sample& s) {
  if (!std::isfinite(s.t_s)) fail("column 't': expected a time in seconds, got an empty or non-finite value");
  if (!(s.t_s > last_t_)) {
    fail("t = " + time_text(s.t_s) + " s is not greater than the previous t = " + time_text(last_t_) +
         " s (time must increase strictly): " +
         (s.t_s == last_t_ ? std::string("a logger that stamped two rows alike? drop the repeated row, or re-stamp it "
                                         "(the previous t plus one sample interval)")
                           : std::string("rows out of order, or a clock that jumped back? sort the rows by t, or "
                                         "split the log where the clock restarted")));
  }
  if (rows_ > 0) {
    const double dt = s.t_s - last_t_;
    if (!rate_stated_ && dt < min_dt_s_) {
      // no stated rate: the shortest interval so far stands for the sample interval
      min_dt_s_ = dt;
      gap_threshold_s_ = driftless::gap_threshold_s(min_dt_s_);
    }
    if (dt > gap_threshold_s_) {
      ++gap_count_;
      if (gaps_.size() < kMaxGapsKept) gaps_.push_back(Gap{last_t_, dt, line_no_});
    } else {
      sum_dt_s_ += dt;
      ++n_dt_;
    }
    if (first_dt_s_.size() < kIntervalsKept) first_dt_s_.push_back(dt);
  } else {
    first_t_s_ = s.t_s;
  }
  const int n = sensors() == 1 ? 3 : 6;
  const bool resting = platforms_resting(s);
  bool missing = false, saturated = false;
  for (int i = 0; i < n; ++i) {
    const double v = i < 3 ? s.gyro1_dps[i] : s.gyro2_dps[i - 3];
    clip_.push(i, v, resting);
    if (std::isnan(v)) {
      missing = true;
      continue;
    }
    const double a = std::fabs(v);
    const int sensor = i < 3 ? 1 : 2;
    const std::size_t si = static_cast<std::size_t>(sensor - 1);
    if (!(a <= gyro_limit_dps_[si])) {
      const std::string_view key = meta_.gyro_full_scale_key(sensor);
      fail(std::string("column '") + std::string(gyro_column_name(i)) + "': " + number_text(v) +
           " deg/s is beyond " + number_text(kFullScaleMargin) + " x the gyro full scale of " +
           number_text(meta_.gyro_full_scale_dps(sensor)) + " deg/s" +
           (!key.empty() ? " stated in " + std::string(key)
                         : std::string(" assumed without a gyro_full_scale_dps key")) +
           "; not a reading a gyro can give (two unlike gyros: gyro1_full_scale_dps / gyro2_full_scale_dps; "
           "see docs/log-format.md)");
    }
    saturated = saturated || a >= full_scale_dps_[si];
  }
  missing_gyro_rows_ += missing ? 1 : 0;
  saturated_rows_ += saturated ? 1 : 0;
}

// one batch of rows, with the lines that are none at their places (Special)
void LogReader::parse_batch(Batch& b) {
  const std::size_t ncol = columns_.size();
  using Kind = Special::Kind;
  b.values.reserve(kBatchRows * ncol);
  b.lines.reserve(kBatchRows);
  try {
    std::string_view line;
    while (b.rows() < kBatchRows) {
      if (!read_line(line)) {
        b.end = true;
        return;
      }
      const std::string_view t = trim(line);
      if (t.empty()) continue;
      if (t.front() == '#') {
        b.specials.push_back(Special{b.rows(), Kind::kComment, std::string(t), lines_read_, false, -1, nullptr});
        continue;
      }
      const std::size_t r = b.rows();
      b.values.resize((r + 1) * ncol);
      std::string problem;
      int bad_column = -1;
      const bool ok = split_row(line, b.values.data() + r * ncol, problem, bad_column);
      if (!ok || tail_unterminated_) {
        // an unterminated last row that parses is still the reader's to judge (take_special)
        b.specials.push_back(Special{r, ok ? Kind::kUnterminated : Kind::kProblem, std::move(problem), lines_read_,
                                     tail_unterminated_, bad_column, nullptr});
      }
      if (!ok) {
        b.values.resize(r * ncol);
        b.end = true;
        return;
      }
      b.lines.push_back(lines_read_);
    }
  } catch (...) {
    b.specials.push_back(Special{b.rows(), Kind::kError, {}, lines_read_, false, -1, std::current_exception()});
    b.end = true;
  }
}

// the parse thread's loop: batches until the file ends or the reader goes away
void LogReader::parse_ahead() {
  Pipeline& p = *pipe_;
  for (bool end = false; !end;) {
    Batch b = p.take_spare();
    parse_batch(b);
    end = b.end;
    if (!p.push(std::move(b))) return;
  }
}

// a line that is no data row, met in order; false when the rows end here
bool LogReader::take_special(const Special& sp) {
  line_no_ = sp.line;
  switch (sp.kind) {
    case Special::Kind::kComment:
      parse_header_line(sp.text);
      return true;
    case Special::Kind::kError:
      std::rethrow_exception(sp.error);
    case Special::Kind::kUnterminated:
    case Special::Kind::kProblem:
      break;
  }
  last_line_unterminated_ = sp.unterminated;
  // the writer ends every row with a newline: an unterminated last line of an incomplete log
  // was cut mid-write, even when what is left happens to parse
  if (last_line_unterminated_ && !meta_.complete() && opts_.tolerate_truncated_tail) {
    dropped_truncated_ = true;
    return false;
  }
  if (sp.kind == Special::Kind::kUnterminated) return true;  // a complete log's last row, kept
  std::string problem = sp.text;
  if (sp.column >= 0) {
    for (const auto& c : detail::kColumns) {
      if (columns_[static_cast<std::size_t>(sp.column)] == c.name) refused_group_ = c.field;
    }
  }
  if (last_line_unterminated_) {
    problem += meta_.complete() ? "; it is the last line and has no line end: the log was cut mid-write (copied while "
                                  "being written?) although it says 'complete: true' (set 'complete: false' to use the rows before it)"
                                : "; it is the last line and has no line end: cut mid-write";
  }
  fail(problem);
}

bool LogReader::next(Sample& out) {
  if (finished_) return false;
  Pipeline& p = *pipe_;
  for (;;) {
    if (p.special < p.cur.specials.size() && p.cur.specials[p.special].before_row == p.row) {
      if (!take_special(p.cur.specials[p.special++])) {
        finished_ = true;
        return false;
      }
      continue;
    }
    if (p.row < p.cur.rows()) break;
    if (p.cur.end) {
      finished_ = true;
      return false;
    }
    if (p.threaded) {
      p.advance();
    } else {
      p.cur.clear();
      p.row = p.special = 0;
      parse_batch(p.cur);
    }
  }
  const std::size_t ncol = columns_.size();
  const double* v = p.cur.values.data() + p.row * ncol;
  line_no_ = p.cur.lines[p.row++];
  std::copy(v, v + ncol, row_.begin());
  for (std::size_t c = 0; c < ncol; ++c) {
    if (target_[c] != nullptr) *target_[c] = row_[c];
  }
  check_row(row_sample_);
  out = row_sample_;
  last_t_ = out.t_s;
  ++rows_;
  return true;
}

std::vector<Sample> read_all(const std::filesystem::path& path, Metadata* meta, std::uint32_t* fields,
                             ReaderOptions opts) {
  LogReader reader(path, opts);
  std::vector<Sample> out;
  Sample s;
  while (reader.next(s)) out.push_back(s);
  if (meta != nullptr) *meta = reader.metadata();
  if (fields != nullptr) *fields = reader.fields();
  return out;
}

double LogReader::stamp_rate_mean_hz() const {
  if (n_dt_ > 0) return double(n_dt_) / sum_dt_s_;
  return rows_ >= 2 ? double(rows_ - 1) / (last_t_ - first_t_s_) : kNaN;
}

double LogReader::stamp_rate_median_hz() const {
  if (first_dt_s_.empty()) return kNaN;
  std::vector<double> dt = first_dt_s_;
  const auto mid = dt.begin() + static_cast<std::ptrdiff_t>(dt.size() / 2);
  std::nth_element(dt.begin(), mid, dt.end());
  return 1.0 / *mid;
}

}  // namespace driftless::log
