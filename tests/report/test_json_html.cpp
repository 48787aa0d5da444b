// JSON and HTML text: one escaper each, exact numbers, null for what JSON cannot hold.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "report/html.hpp"
#include "report/json.hpp"

namespace driftless::report {
namespace {

TEST(Json, StringsAreEscapedPerRfc8259) {
  EXPECT_EQ(json_string("plain"), "\"plain\"");
  EXPECT_EQ(json_string("a\"b\\c"), "\"a\\\"b\\\\c\"");
  EXPECT_EQ(json_string("line\nnext\ttab\r"), "\"line\\nnext\\ttab\\r\"");
  EXPECT_EQ(json_string(std::string("\x01\x1f", 2)), "\"\\u0001\\u001f\"");
  EXPECT_EQ(json_string("°C ü"), "\"°C ü\"");  // UTF-8 passes through
}

TEST(Json, NumbersAreExactAndNonFiniteIsNull) {
  EXPECT_EQ(json_number(0.1), "0.1");
  EXPECT_EQ(json_number(1.0 / 3.0), "0.3333333333333333");
  EXPECT_EQ(json_number(-2e-9), "-2e-09");
  EXPECT_EQ(json_number(std::nan("")), "null");
  EXPECT_EQ(json_number(std::numeric_limits<double>::infinity()), "null");
  EXPECT_EQ(json_array({1.0, 0.5, std::nan("")}), "[1, 0.5, null]");
  EXPECT_EQ(json_array({}), "[]");
}

TEST(Html, EscapesMarkupAndQuotes) {
  EXPECT_EQ(html_escape("a < b && c > \"d\" 'e'"), "a &lt; b &amp;&amp; c &gt; &quot;d&quot; &#39;e&#39;");
}

TEST(Html, Base64MatchesRfc4648Vectors) {
  // RFC 4648 section 10 test vectors
  EXPECT_EQ(base64(""), "");
  EXPECT_EQ(base64("f"), "Zg==");
  EXPECT_EQ(base64("fo"), "Zm8=");
  EXPECT_EQ(base64("foo"), "Zm9v");
  EXPECT_EQ(base64("foob"), "Zm9vYg==");
  EXPECT_EQ(base64("fooba"), "Zm9vYmE=");
  EXPECT_EQ(base64("foobar"), "Zm9vYmFy");
  EXPECT_EQ(base64(std::string("\xff\x00\x80", 3)), "/wCA");
  EXPECT_EQ(inline_png("foo", "a<b"), "<img src=\"data:image/png;base64,Zm9v\" alt=\"a&lt;b\">");
}

}  // namespace
}  // namespace driftless::report
