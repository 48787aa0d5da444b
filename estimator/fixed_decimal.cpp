#include "estimator/fixed_decimal.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace driftless::io {
namespace {

constexpr std::array<double, 18> kPow10 = {1e0, 1e1, 1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,
                                           1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16, 1e17};
constexpr std::array<std::uint64_t, 18> kPow10u = {
    1ull,          10ull,          100ull,          1000ull,          10000ull,          100000ull,
    1000000ull,    10000000ull,    100000000ull,    1000000000ull,    10000000000ull,    100000000000ull,
    1000000000000ull, 10000000000000ull, 100000000000000ull, 1000000000000000ull, 10000000000000000ull,
    100000000000000000ull};

// "00".."99": two digits per division
constexpr std::array<char, 200> make_pairs() {
  std::array<char, 200> t{};
  for (int i = 0; i < 100; ++i) {
    t[static_cast<std::size_t>(2 * i)] = static_cast<char>('0' + i / 10);
    t[static_cast<std::size_t>(2 * i + 1)] = static_cast<char>('0' + i % 10);
  }
  return t;
}
constexpr std::array<char, 200> kPairs = make_pairs();

// writes exactly `width` digits of n (leading zeros), right to left; returns the end
char* digits_fixed_width(char* out, std::uint64_t n, int width) {
  char* const end = out + width;
  char* p = end;
  for (; width >= 2; width -= 2) {
    p -= 2;
    std::memcpy(p, &kPairs[static_cast<std::size_t>(2 * (n % 100))], 2);
    n /= 100;
  }
  if (width == 1) *--p = static_cast<char>('0' + n % 10);
  return end;
}

// writes n without leading zeros ("0" for 0); returns the end
char* digits(char* out, std::uint64_t n) {
  char tmp[20];
  char* p = tmp + sizeof tmp;
  while (n >= 100) {
    p -= 2;
    std::memcpy(p, &kPairs[static_cast<std::size_t>(2 * (n % 100))], 2);
    n /= 100;
  }
  if (n >= 10) {
    p -= 2;
    std::memcpy(p, &kPairs[static_cast<std::size_t>(2 * n)], 2);
  } else {
    *--p = static_cast<char>('0' + n);
  }
  const auto len = static_cast<std::size_t>(tmp + sizeof tmp - p);
  std::memcpy(out, p, len);
  return out + len;
}

// eight ASCII digits at once (little-endian SWAR, as in fast_float): true when all are digits
bool eight_digits(const char* p, std::uint64_t& value) {
  std::uint64_t v;
  std::memcpy(&v, p, 8);
  if (((v + 0x4646464646464646ull) | (v - 0x3030303030303030ull)) & 0x8080808080808080ull) return false;
  v -= 0x3030303030303030ull;
  v = (v * 10) + (v >> 8);
  v = (((v & 0x000000FF000000FFull) * 0x000F424000000064ull) +
       (((v >> 16) & 0x000000FF000000FFull) * 0x0000271000000001ull)) >> 32;
  value = v;
  return true;
}

// digits at p into n (at most 19 in total are kept exact by the caller's check); returns the end
[[gnu::always_inline]] inline const char* read_digits(const char* p, const char* last, std::uint64_t& n, int& count) {
  std::uint64_t eight = 0;
  while (last - p >= 8 && count <= 11 && eight_digits(p, eight)) {
    n = n * 100000000ull + eight;
    count += 8;
    p += 8;
  }
  while (p != last && static_cast<unsigned char>(*p - '0') < 10) {
    n = n * 10 + static_cast<std::uint64_t>(*p - '0');
    ++count;
    ++p;
  }
  return p;
}

char* fallback(char* out, double v, int decimals) {
  return std::to_chars(out, out + 330, v, std::chars_format::fixed, decimals).ptr;
}

}  // namespace

char* write_fixed(char* out, double v, int decimals) {
  if (decimals < 0 || decimals > 17 || !std::isfinite(v)) return fallback(out, v, decimals);
  const double scaled = std::fabs(v) * kPow10[static_cast<std::size_t>(decimals)];
  // the product is within |scaled| * 2^-53 of the exact value; away from a half by more than
  // that (and below 2^52, where the integer part and the fraction are exact), rounding the
  // product to the nearest integer gives the correctly rounded decimal that to_chars writes
  if (!(scaled < 4503599627370496.0)) return fallback(out, v, decimals);
  std::uint64_t n = static_cast<std::uint64_t>(scaled);
  const double frac = scaled - static_cast<double>(n);
  if (std::fabs(frac - 0.5) <= scaled * 2.3e-16 + 1e-300) return fallback(out, v, decimals);
  if (frac > 0.5) ++n;
  char* p = out;
  if (std::signbit(v)) *p++ = '-';
  const std::uint64_t unit = kPow10u[static_cast<std::size_t>(decimals)];
  p = digits(p, n / unit);
  if (decimals > 0) {
    *p++ = '.';
    p = digits_fixed_width(p, n % unit, decimals);
  }
  return p;
}

const char* parse_decimal(const char* first, const char* last, double& out) {
  const char* p = first;
  const bool negative = p != last && *p == '-';
  if (p != last && (*p == '-' || *p == '+')) ++p;
  std::uint64_t n = 0;
  int digits = 0, decimals = 0;
  p = read_digits(p, last, n, digits);
  if (p != last && *p == '.') {
    const int before = digits;
    p = read_digits(p + 1, last, n, digits);
    decimals = digits - before;
  }
  const bool exponent_or_word = p != last && (*p == 'e' || *p == 'E' || *p == 'i' || *p == 'n' || *p == 'I' || *p == 'N');
  if (digits > 0 && digits <= 15 && !exponent_or_word) {
    // n < 10^15 < 2^53 and 10^d are exact doubles: one correctly rounded division
    const double v = decimals == 0 ? static_cast<double>(n)
                                   : static_cast<double>(n) / kPow10[static_cast<std::size_t>(decimals)];
    out = negative ? -v : v;
    return p;
  }
  // long digit strings, exponents, inf, nan: the standard parser ('+' is not its syntax)
  const char* q = first != last && *first == '+' ? first + 1 : first;
  auto [ptr, ec] = std::from_chars(q, last, out);
  return ec == std::errc() ? ptr : nullptr;  // out of range (1e400) is no number either
}

}  // namespace driftless::io
