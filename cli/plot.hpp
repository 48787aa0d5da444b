// Plot output for the driftless commands: a gnuplot script next to its data, rendered to PNG and
// SVG, so users can restyle and re-run it (`gnuplot fig.gp`).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace driftless::cli {

/// Writes DIR/<stem>.gp from `body` (the plot commands, data paths relative to DIR) wrapped with
/// PNG and SVG terminals, then runs gnuplot in DIR. Returns a warning text when gnuplot is missing
/// or fails (the script and data stay for a later run), empty on success.
std::string render_gnuplot(const std::filesystem::path& dir, const std::string& stem, const std::string& body);

/// Writes an Allan table (tau, adev, lo, hi per channel) for gnuplot: columns tau_s then for each
/// channel adev, lo, hi. All curves must share the same taus (octave spacing over equal lengths).
struct AllanTableColumn {
  std::string name;
  std::vector<double> tau_s, adev, lo, hi;
};
void write_allan_table(const std::filesystem::path& path, const std::vector<AllanTableColumn>& cols);

}  // namespace driftless::cli
