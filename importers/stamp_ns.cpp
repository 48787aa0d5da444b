#include "importers/stamp_ns.hpp"

#include <cmath>
#include <initializer_list>
#include <limits>

namespace driftless::importers {

namespace {

// days from 1970-01-01 to a date of the proleptic Gregorian calendar (H. Hinnant's days_from_civil)
std::int64_t days_from_civil(std::int64_t y, unsigned m, unsigned d) {
  y -= m <= 2 ? 1 : 0;
  const std::int64_t era = (y >= 0 ? y : y - 399) / 400;
  const auto yoe = static_cast<unsigned>(y - era * 400);
  const unsigned doy = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;
  const unsigned doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + static_cast<std::int64_t>(doe) - 719468;
}

// `n` digits at p as a number; false when any is not a digit
bool digits_at(const char* p, const char* e, int n, int& v) {
  if (e - p < n) return false;
  v = 0;
  for (int i = 0; i < n; ++i) {
    if (p[i] < '0' || p[i] > '9') return false;
    v = v * 10 + (p[i] - '0');
  }
  return true;
}

}  // namespace

bool parse_datetime_ns(const char* b, const char* e, std::int64_t& ns) {
  // YYYY-MM-DD?HH:MM:SS = 19 characters, then an optional fraction and zone
  int y = 0, mo = 0, d = 0, h = 0, mi = 0, sec = 0;
  if (e - b < 19 || b[4] != '-' || b[7] != '-' || (b[10] != ' ' && b[10] != 'T') || b[13] != ':' || b[16] != ':') return false;
  if (!digits_at(b, e, 4, y) || !digits_at(b + 5, e, 2, mo) || !digits_at(b + 8, e, 2, d) || !digits_at(b + 11, e, 2, h) ||
      !digits_at(b + 14, e, 2, mi) || !digits_at(b + 17, e, 2, sec)) {
    return false;
  }
  static constexpr int kDays[] = {31, 29, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  const bool leap = (y % 4 == 0 && y % 100 != 0) || y % 400 == 0;
  if (mo < 1 || mo > 12 || d < 1 || d > kDays[mo - 1] || (mo == 2 && d == 29 && !leap) || h > 23 || mi > 59 || sec > 60) {
    return false;
  }
  const char* p = b + 19;
  std::int64_t frac_ns = 0;
  if (p < e && (*p == '.' || *p == ',')) {
    std::int64_t scale = 100'000'000;  // ns of the first digit; digits below 1 ns are dropped
    const char* q = ++p;
    for (; p < e && *p >= '0' && *p <= '9'; ++p) {
      frac_ns += (*p - '0') * scale;
      scale /= 10;
    }
    if (p == q) return false;
  }
  std::int64_t offset_s = 0;
  if (p < e && *p == 'Z') {
    ++p;
  } else if (p < e && (*p == '+' || *p == '-')) {
    int oh = 0, om = 0;
    const bool minus = *p == '-';
    if (!digits_at(p + 1, e, 2, oh) || e - p < 6 || p[3] != ':' || !digits_at(p + 4, e, 2, om)) return false;
    offset_s = (minus ? -1 : 1) * (oh * 3600 + om * 60);
    p += 6;
  }
  if (p != e) return false;
  const std::int64_t s = days_from_civil(y, static_cast<unsigned>(mo), static_cast<unsigned>(d)) * 86400 + h * 3600 + mi * 60 + sec -
                         offset_s;
  ns = s * 1'000'000'000 + frac_ns;
  return true;
}

bool parse_stamp_ns(const char* b, const char* e, std::int64_t ns_per_unit, std::int64_t& ns) {
  if (b == e || ns_per_unit <= 0) return false;
  if (e - b >= 19 && b[4] == '-') return ns_per_unit == 1'000'000'000 && parse_datetime_ns(b, e, ns);
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
