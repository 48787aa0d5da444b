// NumPy .npy arrays (format versions 1-3): a 1-D array (one channel) or a C-order 2-D array of
// float32/float64 or integer counts, one sample per row (docs/import.md, npy).
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>

#include "importers/imu_reader.hpp"
#include "importers/reader_factories.hpp"
#include "importers/stamp_ns.hpp"
#include "importers/units.hpp"

namespace driftless::importers {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

enum class Dtype { kF8, kF4, kI2, kI4, kI8 };

// a little-endian element of type T at p, as a double
template <class T>
double load_as(const unsigned char* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return static_cast<double>(v);
}

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
  void column(std::size_t offset, std::size_t rows, double scale, double* out) const;
  void stamps(std::size_t rows, double* t_s) const;
  void set_epoch();
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
  info_.rows_estimate = h_.rows;
  if (time_col_ >= 0) time_scale_ = opt.time_units.empty() ? 1.0 : parse_time_unit(opt.time_units, "--time-units").scale;
  const Unit ru = opt.units.empty() ? Unit{1.0, "deg/s"} : parse_rate_unit(opt.units, "--units");
  for (const auto& c : opt.columns) {
    const int idx = column_index(c, h_.cols, file, "--columns");
    if (std::find(pick_.begin(), pick_.end(), idx) != pick_.end() || idx == time_col_) {
      throw ImportError(file + ": --columns " + c + ": column " + std::to_string(idx + 1) +
                        " is already read as another channel; name each column once");
    }
    pick_.push_back(idx);
  }
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
  set_epoch();
  std::fseek(f_, h_.data_offset, SEEK_SET);
}

// one column of a block of rows, scaled: the element type chosen once per column, not per value
void NpyReader::column(std::size_t offset, std::size_t rows, double scale, double* out) const {
  const std::size_t stride = h_.item * h_.cols;
  const unsigned char* p = raw_.data() + offset;
  auto copy = [&]<class T>(T) {
    for (std::size_t r = 0; r < rows; ++r) out[r] = load_as<T>(p + r * stride) * scale;
  };
  switch (h_.dtype) {
    case Dtype::kF8: return copy(double{});
    case Dtype::kF4: return copy(float{});
    case Dtype::kI2: return copy(std::int16_t{});
    case Dtype::kI4: return copy(std::int32_t{});
    case Dtype::kI8: return copy(std::int64_t{});
  }
}

// the stamps of a block in s from the epoch: integer stamps (ns counts) subtracted in integers
void NpyReader::stamps(std::size_t rows, double* t_s) const {
  const std::size_t stride = h_.item * h_.cols;
  const unsigned char* p = raw_.data() + static_cast<std::size_t>(time_col_) * h_.item;
  const std::int64_t ns_per_unit = ns_per_unit_of(time_scale_);
  if (h_.dtype == Dtype::kI8 && ns_per_unit > 0) {
    for (std::size_t r = 0; r < rows; ++r) {
      std::int64_t v;
      std::memcpy(&v, p + r * stride, sizeof v);
      t_s[r] = seconds_since(v * ns_per_unit, info_.epoch_s);
    }
    return;
  }
  column(static_cast<std::size_t>(time_col_) * h_.item, rows, time_scale_, t_s);
  for (std::size_t r = 0; r < rows; ++r) t_s[r] -= static_cast<double>(info_.epoch_s);
}

// the epoch: the first row's stamp floored to whole seconds
void NpyReader::set_epoch() {
  if (time_col_ < 0 || h_.rows == 0) return;
  raw_.resize(h_.item * h_.cols);
  if (std::fread(raw_.data(), 1, raw_.size(), f_) != raw_.size()) return;
  const std::int64_t ns_per_unit = ns_per_unit_of(time_scale_);
  if (h_.dtype == Dtype::kI8 && ns_per_unit > 0) {
    std::int64_t v;
    std::memcpy(&v, raw_.data() + static_cast<std::size_t>(time_col_) * h_.item, sizeof v);
    info_.epoch_s = epoch_s_of(v * ns_per_unit);
  } else {
    double t = 0.0;
    column(static_cast<std::size_t>(time_col_) * h_.item, 1, time_scale_, &t);
    if (std::isfinite(t)) info_.epoch_s = static_cast<std::int64_t>(std::floor(t));
  }
}

bool NpyReader::read(ImuBlock& out, std::size_t max_rows) {
  out.clear();
  out.values.resize(pick_.size());
  const std::uint64_t rows = std::min<std::uint64_t>(max_rows, h_.rows - next_);
  if (rows == 0) return false;
  const std::size_t row_bytes = h_.item * h_.cols;
  const auto n = static_cast<std::size_t>(rows);
  raw_.resize(n * row_bytes);
  const std::size_t got = std::fread(raw_.data(), 1, raw_.size(), f_);
  if (got != raw_.size()) {
    throw ImportError(where(next_ + got / row_bytes + 1) + ": the file ends before the " + std::to_string(h_.rows) +
                      " rows its header promises");
  }
  for (std::size_t c = 0; c < pick_.size(); ++c) {
    out.values[c].resize(n);
    column(static_cast<std::size_t>(pick_[c]) * h_.item, n, scale_[c], out.values[c].data());
  }
  next_ += rows;
  if (out.bare(info_.has_time)) return true;
  out.t_s.resize(n);
  if (time_col_ >= 0) stamps(n, out.t_s.data());
  else std::fill(out.t_s.begin(), out.t_s.end(), kNaN);
  out.loc.resize(n);
  for (std::size_t r = 0; r < n; ++r) out.loc[r] = next_ - rows + r + 1;
  return true;
}

}  // namespace

std::unique_ptr<ImuReader> make_npy_reader(const std::filesystem::path& path, const ImportOptions& opt) {
  return std::make_unique<NpyReader>(path, opt);
}

}  // namespace driftless::importers
