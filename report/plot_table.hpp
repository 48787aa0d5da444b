// Data tables for plots: the CSV files gnuplot scripts read (report/gnuplot.hpp renders them).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace driftless::report {

/// Writes an Allan table (tau, adev, lo, hi per channel) for gnuplot: columns tau_s then for each
/// channel adev, lo, hi. All curves must share the same taus (octave spacing over equal lengths).
struct AllanTableColumn {
  std::string name;
  std::vector<double> tau_s, adev, lo, hi;
};
void write_allan_table(const std::filesystem::path& path, const std::vector<AllanTableColumn>& cols);

}  // namespace driftless::report
