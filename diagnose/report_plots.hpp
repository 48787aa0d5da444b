// The comparison report's plots (docs/compare.md "Outputs"): residual over time after the
// smoothed bias, windowed rms, Allan deviation against the model's band, rms by regime.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "diagnose/compare.hpp"

namespace driftless::diagnose {

/// A drawn plot: its title and PNG bytes ("" when gnuplot is missing or had nothing to draw).
struct Plot {
  std::string title;
  std::string png;
};

/// Writes the plots' data and gnuplot scripts to `plot_dir` and draws them.
std::vector<Plot> draw_plots(const CompareResult& r, const std::filesystem::path& plot_dir);

}  // namespace driftless::diagnose
