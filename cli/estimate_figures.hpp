// The paper's figures drawn from a `driftless estimate` run (Fig. 4 bias estimates, Fig. 5 Allan
// deviation, Fig. 9 attitude error), as gnuplot scripts next to their data, rendered to PNG and
// SVG (docs/estimator.md section 6). The estimate command feeds the per-sample series and the
// updates while it runs; the figures read the files it wrote (estimate.csv, attitude.csv). A
// figure that cannot say what it claims (no update, no lock, no attitude comparison) is not
// written, and its outcome says why.
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "estimator/filter.hpp"
#include "estimator/sample.hpp"

namespace driftless::cli {

/// estimate.csv's columns (docs/estimator.md section 6), then the truth columns a log with
/// true_bias adds: the writer's header and the figures' column numbers both come from here
inline constexpr std::string_view kEstimateColumns =
    "t,b1_x,b1_y,b1_z,b2_x,b2_y,b2_z,sigma1_x,sigma1_y,sigma1_z,sigma2_x,sigma2_y,sigma2_z,"
    "nis,nis_gate,dim,samples,plat1_deg,plat2_deg,accepted,locked";
inline constexpr std::string_view kEstimateTruthColumns =
    "true_bias1_x,true_bias1_y,true_bias1_z,true_bias2_x,true_bias2_y,true_bias2_z";
/// The 1-based (gnuplot) column of `name` in estimate.csv with its truth columns; throws
/// std::logic_error for a name that is not there.
int estimate_column(std::string_view name);

/// What the figures need beyond the files, collected while the filter runs.
class FigureSeries {
 public:
  /// Adds one sample and what the filter made of it.
  void add(const Sample& s, const est::SampleOutput& o);
  /// Adds one update (accepted or rejected) and the sample it came with (its true_ columns).
  void add_update(const est::UpdateRecord& r, const Sample& s);

  std::vector<double> t_s;                               // s, time of each sample kept
  std::array<std::vector<float>, 3> raw1, cor1;          // sensor 1 output, raw and corrected, deg/s
  std::array<std::vector<float>, 3> raw_rate, cor_rate;  // fused body rate, raw and corrected, deg/s
  bool platforms_moved = false;

  /// One accepted update: time, estimate error against truth (NaN without truth) and sigma.
  struct Update {
    double t_s;
    est::Vector6d error_dps, sigma_dps;
  };
  std::vector<Update> updates;

 private:
  Eigen::Vector3d last_rate_ = Eigen::Vector3d::Zero(), last_raw_rate_ = Eigen::Vector3d::Zero();
};

/// What the figures are drawn from.
struct EstimateFigureInputs {
  const FigureSeries* series = nullptr;
  bool truth = false;           // estimate.csv has true_bias columns
  bool attitude = false;        // attitude.csv holds the comparison (the filter locked, ref_q)
  double sample_rate_hz = kNaN;
  double lock_s = kNaN;         // s, the first row whose correction is locked (NaN: never)
  double start_sigma_dps = kNaN;  // deg/s, the lock criterion (every bias sigma below it)
  double attitude_start_s = kNaN;  // s, the first ref_q at or after lock: where Fig. 9 starts
};

/// What became of one figure.
struct FigureOutcome {
  std::string stem;     // fig4_bias, fig5_allan, fig9_attitude
  bool written = false; // PNG and SVG written
  std::string reason;   // why not (empty when written)
};

/// Writes fig4_bias, fig5_allan (with allan_fig5.csv) and fig9_attitude into `dir`. A figure
/// that cannot be drawn leaves no PNG/SVG behind (an earlier run's are removed).
std::vector<FigureOutcome> write_estimate_figures(const std::filesystem::path& dir, const EstimateFigureInputs& in);

}  // namespace driftless::cli
