// Stage 2 of a comparison: per channel, the block means of the residual and of every regressor
// the log excites, whitened by the channel's bias process (BiasWhitener), and the one MAP solve
// every stage uses: global parameters (shared across channels or not) plus the model's
// run-to-run effects as nuisance with their spread as Gaussian prior. docs/compare.md section 2.
#pragma once

#include <array>
#include <functional>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "diagnose/bias_filter.hpp"
#include "diagnose/effects.hpp"
#include "diagnose/residual.hpp"

namespace driftless::diagnose {

/// The regression data of one gyro channel.
struct ChannelData {
  int s = 0, j = 0;               // sensor, axis
  bool present = true;            // false: sensor 2 of a single-sensor log (no data, no columns)
  std::vector<int> cols;          // regressor columns the log excites
  std::vector<double> prior;      // prior sigma per entry of cols (0 = not a nuisance)
  Eigen::MatrixXf block_cols;     // block means of the columns (blocks x cols), unwhitened
  std::vector<double> z;          // block means of the residual, deg/s
  ChannelNoise noise;             // the model's bias processes and the fitted white density
  Eigen::MatrixXd gram;           // whitened [cols..., z]' [cols..., z]
  // the unit of every objective: the whitened residual variance under the model being tested
  // (the null fit when the channels are built, the selected set's fit after each selection step)
  double sigma2 = 1.0;
  double j0 = 0.0;                // null objective (whitened RSS + prior penalty) / sigma2
  std::size_t m = 0;              // blocks that enter the fit
  /// Position of column `col` in cols, or -1 when the log does not excite it.
  int index(int col) const;
};
using Channels = std::array<ChannelData, 6>;

/// Builds the six channels: block means, the model's noise, white density fitted twice (before
/// and after the nuisance fit), whitened Gram matrices.
Channels build_channels(const ColumnInputs& in, const Residual& res);

/// What a fit estimates: free parameters, and parameters held at given values (file units).
struct FitSpec {
  std::vector<ParamRef> free;
  std::vector<std::pair<ParamRef, double>> fixed;
};

/// The MAP fit of all channels given a spec.
struct FitResult {
  Eigen::VectorXd value, sigma;     // per spec.free, file units (sigma inf where not identified)
  double gain = 0.0;                // drop of the objective (-2 ln L in units of the fitted noise)
  int rank = 0;                     // identified free parameters
};

/// Solves the fit: per channel the nuisance is partialled out (Schur complement with its prior),
/// the free parameters are solved jointly over the channels they drive.
FitResult map_fit(const Channels& ch, const FitSpec& spec);

/// Every coefficient of channel c (cols order) under a fit: the spec's values on their columns,
/// the nuisance at its MAP given them.
Eigen::VectorXd channel_coefficients(const ChannelData& c, int channel, const FitSpec& spec, const FitResult& fit);

/// The channel's block residual after subtracting coefficients `coef` (cols order).
std::vector<double> block_residual(const ChannelData& c, const Eigen::VectorXd& coef);

/// Fits the white density of a channel by maximum likelihood on block residual `z` (golden
/// section on log N) and rebuilds its whitened Gram; returns the relative change of N.
double refit_white(ChannelData& c, const BlockSeries& blocks, std::span<const double> z);

/// Rebuilds a channel's whitened Gram and null fit after its noise model changed.
void rebuild_gram(ChannelData& c, const BlockSeries& blocks);

/// Sets the channel's variance unit to the whitened residual variance left by coefficients
/// `coef` (cols order; all zero: the data's) over its m blocks, and its null objective in it.
void set_variance(ChannelData& c, const Eigen::VectorXd& coef);

/// Maximum-likelihood white density of a channel on block residual `z` (golden section on log N).
double fit_white_density(const ChannelData& c, const BlockSeries& blocks, std::span<const double> z);

/// ln m of the BIC penalty: ln(mean blocks per channel).
double log_blocks(const Channels& ch);

/// Brent's minimum of f on [lo, hi] (golden section with parabolic interpolation) starting at
/// x0, to `tol` in x plus 1e-10 relative.
double brent_min(const std::function<double(double)>& f, double lo, double hi, double x0, double tol);

/// Golden-section minimum of f on [lo, hi].
double golden_min(const std::function<double(double)>& f, double lo, double hi, int iters = 40);

}  // namespace driftless::diagnose
