// The comparison report's figures through the project's one gnuplot runner (report/gnuplot.hpp),
// as PNG bytes for embedding. Internal to diagnose/report*.cpp.
#pragma once

#include <filesystem>
#include <string>

namespace driftless::diagnose::report_text {

/// Runs gnuplot on `script` writing DIR/<stem>.png; returns the PNG bytes, or "" when gnuplot
/// is missing, failed, or found no data to draw (its messages are kept in DIR/<stem>.gp.log).
/// Data files in `script` are named relative to DIR (gnuplot runs there).
std::string gnuplot_png(const std::filesystem::path& dir, const std::string& stem, const std::string& script,
                        int width_px = 900, int height_px = 420);

}  // namespace driftless::diagnose::report_text
