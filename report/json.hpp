// JSON text for machine-readable outputs (summary.json, allan.json, compare.json): one escaper and
// one number form, so every file reads back the doubles the program had (shortest exact text;
// NaN and infinities, which JSON cannot hold, as null).
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace driftless::report {

/// `s` as a JSON string literal, quotes included (RFC 8259 escapes; control characters as \uXXXX).
std::string json_string(std::string_view s);
/// A number as JSON: the shortest exact text, or null when not finite.
std::string json_number(double v);
/// A list of numbers as a JSON array ("[1, 0.5, null]").
std::string json_array(const std::vector<double>& v);

}  // namespace driftless::report
