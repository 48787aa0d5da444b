// The fast fixed-point formatter writes the same bytes as std::to_chars (logs stay byte-identical).
#include <charconv>
#include <cmath>
#include <limits>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "estimator/fixed_decimal.hpp"

namespace driftless::io {
namespace {

std::string reference(double v, int decimals) {
  char buf[400];
  auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed, decimals);
  return std::string(buf, r.ptr);
}

std::string fast(double v, int decimals) {
  char buf[400];
  return std::string(buf, write_fixed(buf, v, decimals));
}

TEST(FixedDecimal, EdgeCasesMatchToChars) {
  const double cases[] = {0.0,       -0.0,        1.0,          -1.0,        0.5,         1.5,        2.5,
                          0.125,     -0.125,      1e-9,         -1e-9,       0.0000005,   -0.0000005, 999999.9999995,
                          1e15,      4.5e15,      4503599627370495.5, 9.007199254740993e15, 1e17, 1e300,
                          -1e300,    5e-324,      std::numeric_limits<double>::infinity(),
                          -std::numeric_limits<double>::infinity(), 90.0, -90.0, 1.0 / 131.0, 0.1, 0.7,
                          2.675,     1.005,       123456.7890123};
  for (double v : cases) {
    for (int d = 0; d <= 17; ++d) EXPECT_EQ(fast(v, d), reference(v, d)) << "v=" << v << " d=" << d;
  }
  EXPECT_EQ(fast(std::numeric_limits<double>::quiet_NaN(), 6), reference(std::numeric_limits<double>::quiet_NaN(), 6));
}

// seeded: values of the sizes logs hold (deg/s, deg, s, quaternions) at every written precision,
// plus exact ties (k + 1/2) / 10^d, where a rounded product could fall on the wrong side
TEST(FixedDecimal, RandomValuesMatchToChars) {
  std::mt19937_64 rng(20261121);
  std::uniform_real_distribution<double> mant(-1.0, 1.0);
  std::uniform_int_distribution<int> expo(-12, 16);
  int checked = 0;
  for (int i = 0; i < 200000; ++i) {
    const double v = mant(rng) * std::pow(10.0, expo(rng));
    const int d = static_cast<int>(rng() % 12);
    ASSERT_EQ(fast(v, d), reference(v, d)) << "v=" << v << " d=" << d;
    ++checked;
  }
  for (int i = 0; i < 20000; ++i) {
    const int d = static_cast<int>(rng() % 10);
    const double v = (static_cast<double>(rng() % 2000000) - 1000000.0 + 0.5) / std::pow(10.0, d);
    ASSERT_EQ(fast(v, d), reference(v, d)) << "v=" << v << " d=" << d;
    ++checked;
  }
  EXPECT_EQ(checked, 220000);
}

// the parser gives the same double as std::from_chars, and stops where the number ends
TEST(ParseDecimal, MatchesFromCharsOnLogTextAndOthers) {
  auto reference = [](const std::string& t) {
    double v = std::nan("");
    const char* b = t.data();
    if (!t.empty() && t[0] == '+') ++b;
    std::from_chars(b, t.data() + t.size(), v);
    return v;
  };
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> mant(-1.0, 1.0);
  std::uniform_int_distribution<int> expo(-8, 14);
  for (int i = 0; i < 100000; ++i) {
    const double v = mant(rng) * std::pow(10.0, expo(rng));
    for (const std::string& t : {fast(v, static_cast<int>(rng() % 11)), std::to_string(v)}) {
      double got = 0.0;
      const char* end = parse_decimal(t.data(), t.data() + t.size(), got);
      ASSERT_EQ(end, t.data() + t.size()) << t;
      ASSERT_EQ(got, reference(t)) << t;
      // inside a row: eight bytes or more follow the number, so its digits are read eight bytes
      // at a time, and the run of digits must end at the comma, whatever its length
      const std::string row = t + ",12345678,9";
      got = 0.0;
      end = parse_decimal(row.data(), row.data() + row.size(), got);
      ASSERT_EQ(end, row.data() + t.size()) << row;
      ASSERT_EQ(got, reference(t)) << row;
    }
  }
  // every length of integer and fraction digits (0-20), followed by a comma and more digits
  for (int whole = 0; whole <= 20; ++whole) {
    for (int frac = 0; frac <= 20; ++frac) {
      std::string t = std::string(static_cast<std::size_t>(whole), '7');
      if (frac > 0) t += "." + std::string(static_cast<std::size_t>(frac), '3');
      if (t.empty()) continue;
      const std::string row = t + ",9876543210";
      double got = 0.0;
      const char* end = parse_decimal(row.data(), row.data() + row.size(), got);
      ASSERT_EQ(end, row.data() + t.size()) << row;
      ASSERT_EQ(got, reference(t)) << row;
    }
  }
  for (const std::string t : {"0", "-0", "+1.5", "1e308", "-2.5E-3", "123456789012345678901234", "0.1234567890123456789",
                               "5.", "inf", "-inf", ".5", "-.25"}) {
    double got = 0.0;
    const char* end = parse_decimal(t.data(), t.data() + t.size(), got);
    ASSERT_EQ(end, t.data() + t.size()) << t;
    EXPECT_EQ(got, reference(t)) << t;
    EXPECT_EQ(std::signbit(got), std::signbit(reference(t))) << t;
  }
  double v = 0.0;
  const std::string row = "12.5,3";
  EXPECT_EQ(parse_decimal(row.data(), row.data() + row.size(), v), row.data() + 4);
  EXPECT_EQ(v, 12.5);
  for (const std::string bad : {"", "-", ".", "abc", "1e400"}) {
    EXPECT_EQ(parse_decimal(bad.data(), bad.data() + bad.size(), v), nullptr) << bad;
  }
  double nan_out = 0.0;
  const std::string nan_text = "nan";
  EXPECT_NE(parse_decimal(nan_text.data(), nan_text.data() + 3, nan_out), nullptr);
  EXPECT_TRUE(std::isnan(nan_out));
}

}  // namespace
}  // namespace driftless::io
