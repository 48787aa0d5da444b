// Text plumbing of the comparison report (JSON and HTML escaping, numbers, base64, gnuplot to
// PNG). Internal to diagnose/report*.cpp.
#pragma once

#include <filesystem>
#include <string>

namespace driftless::diagnose::report_text {

/// A JSON string body with quotes, backslashes and control characters escaped.
std::string json_escape(const std::string& s);
/// A number for JSON: 9 significant digits, null when not finite.
std::string json_number(double v);
/// Text for HTML: <, >, & escaped.
std::string html_escape(const std::string& s);
/// Base64 of bytes (for PNG images embedded in the HTML).
std::string base64(const std::string& bytes);
/// Runs gnuplot on `script` writing DIR/<stem>.png; returns the PNG bytes, or "" when gnuplot
/// is missing, failed, or found no data to draw (its messages are kept in DIR/<stem>.log).
std::string gnuplot_png(const std::filesystem::path& dir, const std::string& stem, const std::string& script,
                        int width_px = 900, int height_px = 420);

}  // namespace driftless::diagnose::report_text
