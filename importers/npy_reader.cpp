// NumPy .npy arrays (format versions 1-3): a 1-D array (one channel) or a C-order 2-D array of
// float32/float64 or integer counts, one sample per row (docs/import.md, npy).
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>

#include "importers/imu_reader.hpp"
#include "importers/reader_factories.hpp"
#include "importers/units.hpp"

namespace driftless::importers {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

enum class Dtype { kF8, kF4, kI2, kI4, kI8 };

struct NpyHeader {
  Dtype dtype = Dtype::kF8;
  std::size_t item = 8;
  std::uint64_t rows = 0;
  std::size_t cols = 1;
  long data_offset = 0;
};

std::string value_of(const std::string& dict, const std::string& key, const std::string& file) {
  const auto k = dict.find("'" + key + "'");
  if (k == std::string::npos) throw ImportError(file + ": .npy header lacks '" + key + "'");
  auto v = dict.find(':', k);
  if (v == std::string::npos) throw ImportError(file + ": .npy header: no value for '" + key + "'");
  ++v;
  while (v < dict.size() && dict[v] == ' ') ++v;
  const char open = dict[v];
  const char close = open == '(' ? ')' : open == '\'' ? '\'' : ',';
  const auto e = dict.find(close, v + 1);
  return dict.substr(v, e == std::string::npos ? std::string::npos : e - v + 1);
}

NpyHeader read_header(std::FILE* f, const std::string& file) {
  unsigned char pre[10];
  if (std::fread(pre, 1, 10, f) != 10 || std::memcmp(pre, "\x93NUMPY", 6) != 0) {
    throw ImportError(file + ": not a NumPy .npy file (no \\x93NUMPY magic)");
  }
  std::size_t hlen = pre[8] | (pre[9] << 8);
  long offset = 10;
  if (pre[6] >= 2) {
    unsigned char more[2];
    if (std::fread(more, 1, 2, f) != 2) throw ImportError(file + ": .npy header cut short");
    hlen |= (static_cast<std::size_t>(more[0]) << 16) | (static_cast<std::size_t>(more[1]) << 24);
    offset = 12;
  }
  std::string dict(hlen, '\0');
  if (std::fread(dict.data(), 1, hlen, f) != hlen) throw ImportError(file + ": .npy header cut short");
  NpyHeader h;
  h.data_offset = offset + static_cast<long>(hlen);
  const std::string descr = value_of(dict, "descr", file);
  struct D { const char* s; Dtype t; std::size_t n; };
  bool known = false;
  for (const D& d : {D{"'<f8'", Dtype::kF8, 8}, D{"'<f4'", Dtype::kF4, 4}, D{"'<i2'", Dtype::kI2, 2},
                     D{"'<i4'", Dtype::kI4, 4}, D{"'<i8'", Dtype::kI8, 8}}) {
    if (descr == d.s) h.dtype = d.t, h.item = d.n, known = true;
  }
  if (!known) throw ImportError(file + ": .npy dtype " + descr + ": expected little-endian <f8, <f4, <i2, <i4 or <i8");
  if (value_of(dict, "fortran_order", file).rfind("True", 0) == 0) {
    throw ImportError(file + ": .npy in Fortran order: save it with numpy.ascontiguousarray(a) first");
  }
  const std::string shape = value_of(dict, "shape", file);
  unsigned long long a = 0, b = 1;
  const int got = std::sscanf(shape.c_str(), "(%llu, %llu", &a, &b);
  if (got < 1) throw ImportError(file + ": .npy shape " + shape + ": expected (rows,) or (rows, columns)");
  h.rows = a;
  h.cols = got == 2 ? static_cast<std::size_t>(b) : 1;
  return h;
}

class NpyReader : public ImuReader {
 public:
  NpyReader(const std::filesystem::path& path, const ImportOptions& opt);
  ~NpyReader() override { std::fclose(f_); }
  bool read(ImuBlock& out, std::size_t max_rows) override;
  std::string where(std::uint64_t loc) const override { return info_.source + ": row " + std::to_string(loc); }

 private:
  double value(const unsigned char* p) const;
  std::FILE* f_ = nullptr;
  NpyHeader h_;
  std::vector<int> pick_;      // channel -> column
  std::vector<double> scale_;  // channel -> to deg/s
  int time_col_ = -1;
  double time_scale_ = 1.0;
  std::uint64_t next_ = 0;
  std::vector<unsigned char> raw_;
};

int column_index(const std::string& s, std::size_t cols, const std::string& file, const char* option) {
  char* end = nullptr;
  const long v = std::strtol(s.c_str(), &end, 10);
  if (end == s.c_str() || *end != '\0' || v < 1 || static_cast<std::size_t>(v) > cols) {
    throw ImportError(file + ": " + option + " '" + s + "': a .npy array has no names; expected a 1-based column index up to " +
                      std::to_string(cols));
  }
  return static_cast<int>(v) - 1;
}

NpyReader::NpyReader(const std::filesystem::path& path, const ImportOptions& opt) {
  const std::string file = path.string();
  f_ = std::fopen(path.c_str(), "rb");
  if (f_ == nullptr) throw ImportError(file + ": cannot open: " + std::strerror(errno));
  try {
    h_ = read_header(f_, file);
  } catch (...) {
    std::fclose(f_);
    throw;
  }
  info_.source = file;
  info_.format = Format::kNpy;
  if (!opt.time_column.empty() && opt.time_column != "none") time_col_ = column_index(opt.time_column, h_.cols, file, "--time-column");
  info_.has_time = time_col_ >= 0;
  if (time_col_ >= 0) time_scale_ = opt.time_units.empty() ? 1.0 : parse_time_unit(opt.time_units, "--time-units").scale;
  const Unit ru = opt.units.empty() ? Unit{1.0, "deg/s"} : parse_rate_unit(opt.units, "--units");
  for (const auto& c : opt.columns) pick_.push_back(column_index(c, h_.cols, file, "--columns"));
  if (pick_.empty()) {
    for (std::size_t c = 0; c < h_.cols; ++c) {
      if (static_cast<int>(c) != time_col_) pick_.push_back(static_cast<int>(c));
    }
  }
  for (std::size_t k = 0; k < pick_.size(); ++k) {
    info_.channels.push_back({"col" + std::to_string(pick_[k] + 1), Quantity::kRate, pick_.size() == 3 ? static_cast<int>(k) : -1});
    scale_.push_back(ru.scale);
  }
  info_.assumptions.push_back(std::to_string(h_.rows) + " rows x " + std::to_string(h_.cols) + " columns");
  info_.assumptions.push_back(opt.units.empty() ? "rates in deg/s: a .npy array carries no units (give --units rad/s if not)"
                                                : "rates in " + ru.name + " (as given)");
  if (time_col_ < 0) info_.assumptions.push_back("no time column: the rate must come from --rate");
  std::fseek(f_, h_.data_offset, SEEK_SET);
}

double NpyReader::value(const unsigned char* p) const {
  switch (h_.dtype) {
    case Dtype::kF8: { double v; std::memcpy(&v, p, 8); return v; }
    case Dtype::kF4: { float v; std::memcpy(&v, p, 4); return v; }
    case Dtype::kI2: { std::int16_t v; std::memcpy(&v, p, 2); return v; }
    case Dtype::kI4: { std::int32_t v; std::memcpy(&v, p, 4); return v; }
    case Dtype::kI8: { std::int64_t v; std::memcpy(&v, p, 8); return static_cast<double>(v); }
  }
  return kNaN;
}

bool NpyReader::read(ImuBlock& out, std::size_t max_rows) {
  out.clear();
  out.values.resize(pick_.size());
  const std::uint64_t rows = std::min<std::uint64_t>(max_rows, h_.rows - next_);
  if (rows == 0) return false;
  const std::size_t row_bytes = h_.item * h_.cols;
  raw_.resize(static_cast<std::size_t>(rows) * row_bytes);
  const std::size_t got = std::fread(raw_.data(), 1, raw_.size(), f_);
  if (got != raw_.size()) {
    throw ImportError(where(next_ + got / row_bytes + 1) + ": the file ends before the " + std::to_string(h_.rows) +
                      " rows its header promises");
  }
  for (auto& v : out.values) v.resize(static_cast<std::size_t>(rows));
  out.t_s.resize(static_cast<std::size_t>(rows));
  out.loc.resize(static_cast<std::size_t>(rows));
  for (std::size_t r = 0; r < rows; ++r) {
    const unsigned char* row = raw_.data() + r * row_bytes;
    for (std::size_t c = 0; c < pick_.size(); ++c) out.values[c][r] = value(row + static_cast<std::size_t>(pick_[c]) * h_.item) * scale_[c];
    out.t_s[r] = time_col_ >= 0 ? value(row + static_cast<std::size_t>(time_col_) * h_.item) * time_scale_ : kNaN;
    out.loc[r] = next_ + r + 1;
  }
  next_ += rows;
  return true;
}

}  // namespace

std::unique_ptr<ImuReader> make_npy_reader(const std::filesystem::path& path, const ImportOptions& opt) {
  return std::make_unique<NpyReader>(path, opt);
}

}  // namespace driftless::importers
