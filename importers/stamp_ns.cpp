#include "importers/stamp_ns.hpp"

#include <cmath>
#include <initializer_list>
#include <limits>

namespace driftless::importers {

bool parse_stamp_ns(const char* b, const char* e, std::int64_t ns_per_unit, std::int64_t& ns) {
  if (b == e || ns_per_unit <= 0) return false;
  const bool negative = *b == '-';
  if (*b == '-' || *b == '+') ++b;
  std::int64_t whole = 0, frac = 0, frac_scale = 1;
  int digits = 0;
  bool dot = false;
  for (; b < e; ++b) {
    if (*b == '.' && !dot) {
      dot = true;
      continue;
    }
    if (*b < '0' || *b > '9') return false;
    ++digits;
    if (!dot) {
      if (whole > (std::numeric_limits<std::int64_t>::max() - (*b - '0')) / 10) return false;  // not 64-bit
      whole = whole * 10 + (*b - '0');
    } else if (frac_scale < 1'000'000'000'000'000'000) {  // digits below 1e-18 of the unit are dropped
      frac = frac * 10 + (*b - '0');
      frac_scale *= 10;
    }
  }
  if (digits == 0 || whole > std::numeric_limits<std::int64_t>::max() / ns_per_unit) return false;
  // the fraction in ns: frac / frac_scale units, rounded to the nearest ns (exact for <= ns digits)
  const auto frac_ns = static_cast<std::int64_t>(std::llround(static_cast<long double>(frac) * ns_per_unit / frac_scale));
  ns = whole * ns_per_unit + frac_ns;
  if (negative) ns = -ns;
  return true;
}

std::int64_t epoch_s_of(std::int64_t ns) {
  const std::int64_t s = ns / 1'000'000'000;
  return ns < 0 && s * 1'000'000'000 != ns ? s - 1 : s;
}

double seconds_since(std::int64_t ns, std::int64_t epoch_s) {
  return static_cast<double>(ns - epoch_s * 1'000'000'000) * 1e-9;
}

std::int64_t ns_per_unit_of(double unit_to_s) {
  for (const std::int64_t n : {1'000'000'000LL, 1'000'000LL, 1'000LL, 1LL}) {
    if (std::fabs(unit_to_s * 1e9 - static_cast<double>(n)) < 1e-6 * static_cast<double>(n)) return n;
  }
  return 0;
}

}  // namespace driftless::importers
