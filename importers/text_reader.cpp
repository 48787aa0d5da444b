// Delimited text and EuRoC / TUM-VI imu0/data.csv: the layout from the first lines, then rows
// streamed in 8 MB chunks, only the used fields parsed (fast_float).
#include "importers/text_reader.hpp"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <limits>

#include <fast_float/fast_float.h>

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
  info_.assumptions = layout_.assumptions;
  slot_.assign(layout_.fields, -1);
  for (std::size_t c = 0; c < layout_.picks.size(); ++c) {
    info_.channels.push_back(layout_.picks[c].channel);
    slot_[static_cast<std::size_t>(layout_.picks[c].index)] = static_cast<int>(c);
  }
  if (layout_.time_index >= 0) slot_[static_cast<std::size_t>(layout_.time_index)] = kTimeSlot;
  std::rewind(file_);
}

TextReader::~TextReader() {
  if (file_ != nullptr) std::fclose(file_);
}

std::string ImuReader::where(std::uint64_t loc) const { return info_.source + ":" + std::to_string(loc); }

bool TextReader::next_line(std::string_view& line) {
  for (;;) {
    const void* nl = pos_ < buf_.size() ? std::memchr(buf_.data() + pos_, '\n', buf_.size() - pos_) : nullptr;
    if (nl != nullptr) {
      const std::size_t end = static_cast<std::size_t>(static_cast<const char*>(nl) - buf_.data());
      line = std::string_view(buf_.data() + pos_, end - pos_);
      pos_ = end + 1;
      ++line_no_;
      return true;
    }
    if (eof_) {
      if (pos_ >= buf_.size()) return false;
      line = std::string_view(buf_.data() + pos_, buf_.size() - pos_);
      pos_ = buf_.size();
      ++line_no_;
      return true;
    }
    buf_.erase(0, pos_);
    pos_ = 0;
    const std::size_t old = buf_.size();
    buf_.resize(old + kChunk);
    const std::size_t got = std::fread(buf_.data() + old, 1, kChunk, file_);
    buf_.resize(old + got);
    if (got == 0) {
      if (std::ferror(file_)) throw ImportError(path_ + ": read error: " + std::strerror(errno));
      eof_ = true;
    }
  }
}

void TextReader::parse_row(std::string_view line, ImuBlock& out) {
  const char sep = layout_.separator;
  const char* p = line.data();
  const char* e = p + line.size();
  if (e > p && e[-1] == '\r') --e;
  std::size_t k = 0;
  double t = kNaN;
  const std::size_t row = out.t_s.size();
  for (auto& v : out.values) v.push_back(kNaN);
  for (;;) {
    if (sep == ' ') {
      while (p < e && (*p == ' ' || *p == '\t')) ++p;
      if (p == e) break;
    }
    const char* q = p;
    if (sep == ' ') {
      while (q < e && *q != ' ' && *q != '\t') ++q;
    } else {
      const void* s = std::memchr(p, sep, static_cast<std::size_t>(e - p));
      q = s == nullptr ? e : static_cast<const char*>(s);
    }
    if (k < slot_.size() && slot_[k] != -1) {
      double v = 0.0;
      if (!parse_span(p, q, v)) {
        const std::string name = slot_[k] == kTimeSlot ? "time" : info_.channels[static_cast<std::size_t>(slot_[k])].name;
        throw ImportError(where(line_no_) + ": column '" + name + "' (" + std::to_string(k + 1) +
                          "): expected a number, got '" + std::string(p, q) + "'");
      }
      if (slot_[k] == kTimeSlot) t = v * layout_.time_scale;
      else out.values[static_cast<std::size_t>(slot_[k])][row] = v * layout_.picks[static_cast<std::size_t>(slot_[k])].scale;
    }
    ++k;
    if (q == e) break;
    p = q + 1;
  }
  if (k != layout_.fields) {
    throw ImportError(where(line_no_) + ": expected " + std::to_string(layout_.fields) + " fields as in line " +
                      std::to_string(layout_.data_line) + ", got " + std::to_string(k));
  }
  out.t_s.push_back(t);
  out.loc.push_back(line_no_);
}

bool TextReader::read(ImuBlock& out, std::size_t max_rows) {
  out.clear();
  out.values.resize(info_.channels.size());
  std::string_view line;
  while (out.rows() < max_rows && next_line(line)) {
    if (line_no_ < layout_.data_line) continue;
    std::size_t i = 0;
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    if (i == line.size() || line[i] == '#' || line[i] == '%') continue;
    parse_row(line, out);
  }
  return out.rows() > 0;
}

}  // namespace driftless::importers
