#include "report/json.hpp"

#include <cmath>

#include "estimator/numbers.hpp"

namespace driftless::report {

std::string json_string(std::string_view s) {
  static const char* kHex = "0123456789abcdef";
  std::string o = "\"";
  for (char c : s) {
    const auto u = static_cast<unsigned char>(c);
    switch (c) {
      case '"': o += "\\\""; break;
      case '\\': o += "\\\\"; break;
      case '\n': o += "\\n"; break;
      case '\r': o += "\\r"; break;
      case '\t': o += "\\t"; break;
      default:
        if (u < 0x20) {
          o += "\\u00";
          o += kHex[u >> 4];
          o += kHex[u & 15];
        } else {
          o += c;
        }
    }
  }
  return o + "\"";
}

std::string json_number(double v) { return std::isfinite(v) ? exact_number(v) : "null"; }

std::string json_array(const std::vector<double>& v) {
  std::string o = "[";
  for (std::size_t i = 0; i < v.size(); ++i) o += (i ? ", " : "") + json_number(v[i]);
  return o + "]";
}

}  // namespace driftless::report
