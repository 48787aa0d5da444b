// Delimited text and EuRoC / TUM-VI imu0/data.csv: the layout from the first lines, then rows
// parsed where the mapped file lies (a pipe: read in 8 MB chunks), only the used fields parsed
// (fast_float).
#include "importers/text_reader.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <exception>
#include <limits>
#include <thread>

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fast_float/fast_float.h>

#include "estimator/huge_pages.hpp"
#include "importers/stamp_ns.hpp"

namespace driftless::importers {
namespace {

constexpr std::size_t kChunk = 8u << 20;
constexpr std::size_t kHeadBytes = 256u << 10;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// a field [b, e) as a number, blanks trimmed; empty or nan -> NaN
bool parse_span(const char* b, const char* e, double& out) {
  while (b < e && (*b == ' ' || *b == '\t')) ++b;
  while (e > b && (e[-1] == ' ' || e[-1] == '\t' || e[-1] == '\r')) --e;
  if (b == e) return out = kNaN, true;
  if (*b == '+') ++b;
  const auto r = fast_float::from_chars(b, e, out);
  if (r.ec == std::errc() && r.ptr == e) return true;
  return parse_field(std::string_view(b, static_cast<std::size_t>(e - b)), out);  // "nan" spellings
}

// the end of the field that starts at p (its separator, or e)
const char* field_end(const char* p, const char* e, char sep) {
  if (sep == ' ') {
    while (p < e && *p != ' ' && *p != '\t') ++p;
    return p;
  }
  const void* s = std::memchr(p, sep, static_cast<std::size_t>(e - p));
  return s == nullptr ? e : static_cast<const char*>(s);
}

// a plain number field at p, parsed where it stands: its end is found from the number's own end
// (no scan for the separator first). q: the field's end. False when the field is anything else
// (empty, a nan spelling, trailing text): the caller then takes the general path, which gives the
// same value for every field this one accepts.
bool quick_value(const char* p, const char* e, char sep, const char*& q, double& v) {
  const auto blank = [sep](char c) { return (c == ' ' || c == '\t') && c != sep; };
  while (p < e && blank(*p)) ++p;
  if (p < e && *p == '+') ++p;
  const auto r = fast_float::from_chars(p, e, v);
  if (r.ec != std::errc()) return false;
  q = r.ptr;
  if (sep == ' ') return q == e || *q == ' ' || *q == '\t';
  while (q < e && blank(*q)) ++q;
  return q == e || *q == sep;
}

// rows in the file if every line is as long as those of the first chunk
std::uint64_t estimate_rows(std::string_view head, std::uintmax_t file_bytes) {
  const auto lines = static_cast<std::size_t>(std::count(head.begin(), head.end(), '\n'));
  if (lines == 0 || head.empty()) return 0;
  const double bytes_per_line = static_cast<double>(head.size()) / static_cast<double>(lines);
  return static_cast<std::uint64_t>(static_cast<double>(file_bytes) / bytes_per_line) + 1;
}

// room for `rows` rows at once (growing by doubling copies and faults in 2x the pages), on huge pages
void reserve_rows(ImuBlock& b, std::size_t rows, bool has_time) {
  if (!b.bare(has_time)) {
    b.t_s.reserve(rows);
    b.loc.reserve(rows);
    est::advise_huge_pages(b.t_s);
    est::advise_huge_pages(b.loc);
  }
  for (auto& v : b.values) {
    v.reserve(rows);
    est::advise_huge_pages(v);
  }
}

// the rows of `from` behind those of `to`
void append_block(ImuBlock& to, const ImuBlock& from) {
  to.t_s.insert(to.t_s.end(), from.t_s.begin(), from.t_s.end());
  to.loc.insert(to.loc.end(), from.loc.begin(), from.loc.end());
  for (std::size_t c = 0; c < to.values.size(); ++c) {
    to.values[c].insert(to.values[c].end(), from.values[c].begin(), from.values[c].end());
  }
}

// the end of the first n lines of [b, e) (each ends in a newline; e when there are fewer), and
// how many lines that is: newlines counted 64 kB at a time, the last piece walked line by line
const char* after_lines(const char* b, const char* e, std::size_t n, std::size_t& lines) {
  constexpr std::ptrdiff_t kPiece = 1 << 16;
  lines = 0;
  while (e - b > kPiece) {
    const auto k = static_cast<std::size_t>(std::count(b, b + kPiece, '\n'));
    if (k >= n - lines) break;
    lines += k;
    b += kPiece;
  }
  for (; lines < n && b < e; ++lines) {
    const void* nl = std::memchr(b, '\n', static_cast<std::size_t>(e - b));
    if (nl == nullptr) return e;  // (a last line without its newline is left to the caller)
    b = static_cast<const char*>(nl) + 1;
  }
  return b;
}

}  // namespace

TextReader::TextReader(const std::filesystem::path& path, const ImportOptions& opt, bool euroc) : path_(path.string()) {
  file_ = std::fopen(path.c_str(), "rb");
  if (file_ == nullptr) throw ImportError(path_ + ": cannot open: " + std::strerror(errno));
  std::string head(kHeadBytes, '\0');
  head.resize(std::fread(head.data(), 1, kHeadBytes, file_));
  if (head.empty()) throw ImportError(path_ + ": empty file; expected rows of numbers");
  // whole lines only
  const auto last_nl = head.rfind('\n');
  if (last_nl != std::string::npos && head.size() == kHeadBytes) head.resize(last_nl + 1);
  layout_ = detect_text_layout(head, path_, opt, euroc);
  info_.source = path_;
  info_.format = euroc ? Format::kEuroc : Format::kText;
  info_.has_time = layout_.time_index >= 0;
  info_.nominal_rate_hz = layout_.nominal_rate_hz;
  info_.rows_estimate = estimate_rows(head, std::filesystem::file_size(path));
  info_.assumptions = layout_.assumptions;
  slot_.assign(layout_.fields, -1);
  for (std::size_t c = 0; c < layout_.picks.size(); ++c) {
    info_.channels.push_back(layout_.picks[c].channel);
    slot_[static_cast<std::size_t>(layout_.picks[c].index)] = static_cast<int>(c);
  }
  if (layout_.time_index >= 0) slot_[static_cast<std::size_t>(layout_.time_index)] = kTimeSlot;
  if (info_.has_time) set_epoch(head);
  std::rewind(file_);
  if (map_file()) {
    eof_ = true;
    len_ = map_bytes_ - cut_tail_bytes();
  }
}

// A recording stopped mid-write (a crash, a power cut, a copy of a file still being written) ends in a
// line without its line end and with fewer fields than the rows: that line is left out and said. Any
// other malformed line stays an error; a last line without a line end but with every field is a row.
std::size_t TextReader::cut_tail_bytes() {
  if (map_bytes_ == 0 || map_[map_bytes_ - 1] == '\n') return 0;
  const char* e = map_ + map_bytes_;
  const char* b = e;
  while (b > map_ && b[-1] != '\n') --b;
  if (b == map_) return 0;  // one line only: the layout has already refused or taken it
  std::vector<std::string_view> f;
  split_fields(std::string_view(b, static_cast<std::size_t>(e - b)), layout_.separator, f);
  if (f.empty() || f.size() >= layout_.fields) return 0;
  info_.assumptions.push_back("the last line is cut off (no line end, " + std::to_string(f.size()) + " of " +
                              std::to_string(layout_.fields) + " fields: a recording stopped mid-write): left out");
  return static_cast<std::size_t>(e - b);
}

TextReader::~TextReader() {
  if (map_ != nullptr) ::munmap(const_cast<char*>(map_), map_bytes_);
  if (file_ != nullptr) std::fclose(file_);
}

// a regular file is parsed where the page cache holds it: no copy into a buffer, no refills
bool TextReader::map_file() {
  struct stat st {};
  const int fd = ::fileno(file_);
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) || st.st_size <= 0) return false;
  const auto bytes = static_cast<std::size_t>(st.st_size);
  void* p = ::mmap(nullptr, bytes, PROT_READ, MAP_PRIVATE, fd, 0);
  if (p == MAP_FAILED) return false;
  ::madvise(p, bytes, MADV_SEQUENTIAL);
  map_ = static_cast<const char*>(p);
  map_bytes_ = bytes;
  return true;
}

void TextReader::release_parsed() {
  constexpr std::size_t kReleaseBytes = 64u << 20;
  if (map_ == nullptr || pos_ >= len_) return;  // (at the end the whole map goes at once)
  const auto page = static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
  const std::size_t upto = pos_ / page * page;
  if (upto < released_ + kReleaseBytes) return;
  ::madvise(const_cast<char*>(map_) + released_, upto - released_, MADV_DONTNEED);
  released_ = upto;
}

std::string ImuReader::where(std::uint64_t loc) const { return info_.source + ":" + std::to_string(loc); }

// the unread tail moved to the front, then one more chunk read behind it
void TextReader::refill() {
  const std::size_t carry = len_ - pos_;
  if (carry + kChunk > cap_) {
    const std::size_t cap = std::max(2 * kChunk, carry + kChunk);
    auto bigger = std::make_unique_for_overwrite<char[]>(cap);
    if (carry > 0) std::memcpy(bigger.get(), buf_.get() + pos_, carry);
    buf_ = std::move(bigger);
    cap_ = cap;
  } else if (carry > 0) {
    std::memmove(buf_.get(), buf_.get() + pos_, carry);
  }
  pos_ = 0;
  len_ = carry;
  const std::size_t got = std::fread(buf_.get() + len_, 1, kChunk, file_);
  len_ += got;
  if (got == 0) {
    if (std::ferror(file_)) throw ImportError(path_ + ": read error: " + std::strerror(errno));
    eof_ = true;
  }
}

bool TextReader::next_line(std::string_view& line) {
  for (;;) {
    const char* base = data();
    const void* nl = pos_ < len_ ? std::memchr(base + pos_, '\n', len_ - pos_) : nullptr;
    if (nl != nullptr) {
      const std::size_t end = static_cast<std::size_t>(static_cast<const char*>(nl) - base);
      line = std::string_view(base + pos_, end - pos_);
      pos_ = end + 1;
      ++line_no_;
      return true;
    }
    if (eof_) {
      if (pos_ >= len_) return false;
      line = std::string_view(base + pos_, len_ - pos_);
      pos_ = len_;
      ++line_no_;
      return true;
    }
    refill();
  }
}

// the epoch: the first data row's stamp, floored to whole seconds (docs/import.md, time)
void TextReader::set_epoch(std::string_view head) {
  ns_per_unit_ = ns_per_unit_of(layout_.time_scale);
  std::size_t line_no = 0, b = 0;
  std::vector<std::string_view> fields;
  for (std::size_t e = 0; b < head.size(); b = e + 1) {
    e = std::min(head.find('\n', b), head.size());
    if (++line_no < layout_.data_line) continue;
    split_fields(head.substr(b, e - b), layout_.separator, fields);
    if (fields.size() != layout_.fields) continue;
    const auto& f = fields[static_cast<std::size_t>(layout_.time_index)];
    std::int64_t ns = 0;
    double v = 0.0;
    if (ns_per_unit_ > 0 && parse_stamp_ns(f.data(), f.data() + f.size(), ns_per_unit_, ns)) {
      info_.epoch_s = epoch_s_of(ns);
      return;
    }
    if (parse_field(f, v) && std::isfinite(v)) {
      info_.epoch_s = static_cast<std::int64_t>(std::floor(v * layout_.time_scale));
      return;
    }
  }
}

bool TextReader::stamp_s(const char* b, const char* e, double& t_s) const {
  while (b < e && (*b == ' ' || *b == '\t')) ++b;
  while (e > b && (e[-1] == ' ' || e[-1] == '\t' || e[-1] == '\r')) --e;
  std::int64_t ns = 0;
  if (ns_per_unit_ > 0 && parse_stamp_ns(b, e, ns_per_unit_, ns)) {
    t_s = seconds_since(ns, info_.epoch_s);
    return true;
  }
  double v = 0.0;
  if (!parse_span(b, e, v)) return false;
  t_s = v * layout_.time_scale - static_cast<double>(info_.epoch_s);
  return true;
}

void TextReader::parse_row(std::string_view line, std::uint64_t line_no, ImuBlock& out) const {
  const char sep = layout_.separator;
  const char* p = line.data();
  const char* e = p + line.size();
  if (e > p && e[-1] == '\r') --e;
  std::size_t k = 0;
  double t = kNaN, value = 0.0;
  const std::size_t row = out.rows();
  for (auto& v : out.values) v.push_back(kNaN);
  for (;;) {
    if (sep == ' ') {
      while (p < e && (*p == ' ' || *p == '\t')) ++p;
      if (p == e) break;
    }
    const int slot = k < slot_.size() ? slot_[k] : -1;
    const char* q = p;
    if (slot >= 0 && quick_value(p, e, sep, q, value)) {
      out.values[static_cast<std::size_t>(slot)][row] = value * layout_.picks[static_cast<std::size_t>(slot)].scale;
    } else {
      q = field_end(p, e, sep);
      if (slot != -1 && !(slot == kTimeSlot ? stamp_s(p, q, t) : parse_span(p, q, value))) {
        const std::string name = slot == kTimeSlot ? "time" : info_.channels[static_cast<std::size_t>(slot)].name;
        throw ImportError(where(line_no) + ": column '" + name + "' (" + std::to_string(k + 1) +
                          "): expected a number, got '" + std::string(p, q) + "'");
      }
      if (slot >= 0) out.values[static_cast<std::size_t>(slot)][row] = value * layout_.picks[static_cast<std::size_t>(slot)].scale;
    }
    ++k;
    if (q == e) break;
    p = q + 1;
  }
  if (k != layout_.fields) {
    throw ImportError(where(line_no) + ": expected " + std::to_string(layout_.fields) + " fields as in line " +
                      std::to_string(layout_.data_line) + ", got " + std::to_string(k));
  }
  if (out.bare(info_.has_time)) return;
  out.t_s.push_back(t);
  out.loc.push_back(line_no);
}

void TextReader::take_line(std::string_view line, std::uint64_t line_no, ImuBlock& out) const {
  if (line_no < layout_.data_line) return;
  std::size_t i = 0;
  while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
  if (i == line.size() || line[i] == '#' || line[i] == '%') return;
  parse_row(line, line_no, out);
}

std::uint64_t TextReader::parse_lines(const char* b, const char* e, std::uint64_t first_line, ImuBlock& out) const {
  std::uint64_t no = first_line;
  for (; b < e; ++no) {
    const char* nl = static_cast<const char*>(std::memchr(b, '\n', static_cast<std::size_t>(e - b)));
    const char* end = nl == nullptr ? e : nl;
    take_line(std::string_view(b, static_cast<std::size_t>(end - b)), no, out);
    b = end + 1;
  }
  return no - first_line;
}

// The second half is parsed before the first half's lines are counted: its lines are numbered
// from the data line (it lies past the preamble, which is within the first 256 kB) and renumbered
// after the join; on an error it is parsed again with the true numbers, so the message names the
// right line.
bool TextReader::parse_buffered_in_two(ImuBlock& out, std::size_t room) {
  constexpr std::size_t kMinBytes = 1u << 20;
  if (!eof_ && len_ - pos_ < kChunk / 2) refill();
  const char* b = data() + pos_;
  const char* e = b + (len_ - pos_);
  while (e > b && e[-1] != '\n') --e;  // whole lines only
  if (static_cast<std::size_t>(e - b) < kMinBytes) return false;
  // no more lines than rows may still come (a line holds at most one row, and at least one byte)
  if (room < static_cast<std::size_t>(e - b)) {
    std::size_t lines = 0;
    e = after_lines(b, e, room, lines);
    if (static_cast<std::size_t>(e - b) < kMinBytes) return false;
  }
  const char* half = b + (e - b) / 2;
  const char* mid = static_cast<const char*>(std::memchr(half, '\n', static_cast<std::size_t>(e - half))) + 1;
  side_.clear();
  side_.values.resize(out.values.size());
  side_.bare_untimed = out.bare_untimed;
  const std::size_t cap = out.values.empty() ? out.t_s.capacity() : out.values.front().capacity();
  reserve_rows(side_, cap / 2 + cap / 16, info_.has_time);
  std::exception_ptr side_error;
  std::uint64_t second_lines = 0;
  std::thread helper([&] {
    try {
      second_lines = parse_lines(mid, e, layout_.data_line, side_);
    } catch (...) {
      side_error = std::current_exception();
    }
  });
  std::uint64_t first_lines = 0;
  try {
    first_lines = parse_lines(b, mid, line_no_ + 1, out);
  } catch (...) {
    helper.join();  // the earlier line's error is the one reported
    throw;
  }
  helper.join();
  const std::uint64_t second_first = line_no_ + first_lines + 1;
  if (side_error) {
    side_.clear();
    parse_lines(mid, e, second_first, side_);  // throws the same error, numbered truly
    std::rethrow_exception(side_error);
  }
  for (auto& l : side_.loc) l += second_first - layout_.data_line;
  append_block(out, side_);
  pos_ += static_cast<std::size_t>(e - b);
  line_no_ += first_lines + second_lines;
  return true;
}

bool TextReader::read(ImuBlock& out, std::size_t max_rows) {
  out.clear();
  out.values.resize(info_.channels.size());
  reserve_rows(out, std::min<std::uint64_t>(max_rows, info_.rows_estimate + 1024), info_.has_time);
  std::string_view line;
  while (out.rows() < max_rows && parse_buffered_in_two(out, max_rows - out.rows())) {
  }
  // what is left of the block (too little for two threads, or the file's end): line by line
  while (out.rows() < max_rows && next_line(line)) take_line(line, line_no_, out);
  release_parsed();
  return out.rows() > 0;
}

}  // namespace driftless::importers
