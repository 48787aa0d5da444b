// The paper's figures drawn from a `driftless estimate` run (Fig. 4 bias estimates, Fig. 5 Allan
// deviation, Fig. 9 attitude error), as gnuplot scripts next to their data, rendered to PNG and
// SVG (docs/estimator.md section 6). The estimate command feeds the per-sample series while it
// runs; the figures read the files it wrote (estimate.csv, attitude.csv).
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "estimator/filter.hpp"
#include "estimator/sample.hpp"

namespace driftless::cli {

/// The per-sample series Fig. 5 needs, collected while the filter runs (deg/s).
class FigureSeries {
 public:
  /// Adds one sample and what the filter made of it.
  void add(const Sample& s, const est::SampleOutput& o);
  std::array<std::vector<float>, 3> raw1, cor1;          // sensor 1 output, raw and corrected
  std::array<std::vector<float>, 3> raw_rate, cor_rate;  // fused body rate, raw and corrected
  bool platforms_moved = false;

 private:
  Eigen::Vector3d last_rate_ = Eigen::Vector3d::Zero(), last_raw_rate_ = Eigen::Vector3d::Zero();
};

/// What the figures are drawn from.
struct EstimateFigureInputs {
  const FigureSeries* series = nullptr;
  bool truth = false;     // estimate.csv has true_bias columns
  bool attitude = false;  // attitude.csv holds the comparison
  double sample_rate_hz = kNaN;
};

/// Writes fig4_bias, fig5_allan (with allan_fig5.csv) and fig9_attitude into `dir`. Returns one
/// warning per figure that could not be rendered.
std::vector<std::string> write_estimate_figures(const std::filesystem::path& dir, const EstimateFigureInputs& in);

}  // namespace driftless::cli
