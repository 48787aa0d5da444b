// The one exact number formatter and the strict parser: shortest round-trip text, fixed notation
// for decimal exponents -4..15 (like Python's repr and fmt's "{}"), scientific beyond.
#include <gtest/gtest.h>

#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>

#include "estimator/numbers.hpp"

namespace driftless {
namespace {

TEST(ExactNumber, WritesTheShortestTextInReprStyle) {
  EXPECT_EQ(exact_number(0.0), "0");
  EXPECT_EQ(exact_number(-0.0), "-0");
  EXPECT_EQ(exact_number(600.0), "600");
  EXPECT_EQ(exact_number(0.005), "0.005");
  EXPECT_EQ(exact_number(0.0001), "0.0001");
  EXPECT_EQ(exact_number(1e-5), "1e-05");
  EXPECT_EQ(exact_number(2e-5), "2e-05");
  EXPECT_EQ(exact_number(1e-14), "1e-14");
  EXPECT_EQ(exact_number(10800.0), "10800");
  EXPECT_EQ(exact_number(1e15), "1000000000000000");
  EXPECT_EQ(exact_number(1e16), "1e+16");
  EXPECT_EQ(exact_number(-2.5), "-2.5");
  EXPECT_EQ(exact_number(0.1), "0.1");
  EXPECT_EQ(exact_number(1.0 / 3.0), "0.3333333333333333");
  EXPECT_EQ(exact_number(0.9999), "0.9999");
  EXPECT_EQ(exact_number(123456.789), "123456.789");
  EXPECT_EQ(exact_number(std::nan("")), "nan");
  EXPECT_EQ(exact_number(std::numeric_limits<double>::infinity()), "inf");
  EXPECT_EQ(exact_number(-std::numeric_limits<double>::infinity()), "-inf");
}

TEST(ExactNumber, RoundTripsRandomDoublesWithTheShortestDigits) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> mant(-10.0, 10.0);
  std::uniform_int_distribution<int> expo(-30, 30);
  for (int i = 0; i < 20000; ++i) {
    const double v = mant(rng) * std::pow(10.0, expo(rng));
    const std::string s = exact_number(v);
    double back = 0.0;
    ASSERT_TRUE(parse_decimal(s, back)) << s;
    ASSERT_EQ(back, v) << s;
    // as few significant digits as std::to_chars' shortest form
    char buf[64];
    const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::scientific);
    const std::string sci(buf, r.ptr);
    std::size_t want = 0, got = 0;
    for (char c : sci.substr(0, sci.find('e'))) want += (c >= '0' && c <= '9');
    const std::string mantissa = s.substr(0, s.find('e'));
    std::string digits;
    for (char c : mantissa) if (c >= '0' && c <= '9') digits += c;
    digits.erase(0, digits.find_first_not_of('0'));                 // leading zeros of 0.000x
    if (s.find('e') == std::string::npos && s.find('.') == std::string::npos)
      digits.erase(digits.find_last_not_of('0') + 1);                // trailing zeros of 1200
    got = digits.size();
    ASSERT_EQ(got, want) << s << " vs " << sci;
  }
}

TEST(ParseDecimal, IsStrict) {
  double v = 0.0;
  EXPECT_TRUE(parse_decimal("+1.5", v));
  EXPECT_EQ(v, 1.5);
  EXPECT_TRUE(parse_decimal("-2e3", v));
  EXPECT_EQ(v, -2000.0);
  EXPECT_FALSE(parse_decimal("", v));
  EXPECT_FALSE(parse_decimal("1.5 ", v));
  EXPECT_FALSE(parse_decimal(" 1.5", v));
  EXPECT_FALSE(parse_decimal("1,5", v));
  EXPECT_FALSE(parse_decimal("+-1", v));
  EXPECT_FALSE(parse_decimal("abc", v));
  EXPECT_FALSE(parse_decimal("1e999", v));
}

}  // namespace
}  // namespace driftless
