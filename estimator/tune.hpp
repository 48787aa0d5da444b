// Tuning from the data (`estimate --tune auto`, docs/estimator.md section 6.2): a first pass over
// the log measures the white noise and the bias wander the filter's R and Q stand for, so a
// sensor the defaults do not describe (another MEMS part, 10x the MPU6050's noise) needs no
// hand-written configuration.
//  - noise density N: every standstill is cut into blocks of block_s; the eq. (2) residual
//    r = M1 y1 - M2 y2 (body rate and Earth rate cancel) of consecutive blocks differs by noise,
//    E|r_a - r_b|^2 = 6 sigma^2 (1/n_a + 1/n_b) with sigma^2 = N^2 f_s per sample and axis (an
//    Allan variance of the residual at tau = block_s, where the white noise dominates), plus, on
//    a moving box, what its motion leaves in r through sensor errors the residual does not cancel
//    (scale factor and misalignment times the body-rate change, g-sensitivity times the change of
//    specific force). Per position pair that part is linear in the change of the fused body rate
//    and of the specific force; it is fitted by least squares and the noise is measured in what
//    is left, E[SS] = 6 sigma^2 (pairs - fitted coefficients per axis);
//  - bias random walk K (Q = K^2 per second): visits to the same platform positions differ by the
//    bias change plus noise (and the same motion term, taken out with the same fit when the fit
//    is significant; its coefficients' own error adds 6 sigma^2 dx^T (X^T W X)^-1 dx),
//    E|r_j - r_k|^2 = 6 K^2 dt + 6 sigma^2 (1/n_j + 1/n_k).
// Eigen + std only.
#pragma once

#include <cstdint>
#include <map>
#include <utility>

#include "estimator/config.hpp"
#include "estimator/filter.hpp"
#include "estimator/log.hpp"
#include "estimator/standstill.hpp"

namespace driftless::est {

/// What the first pass measured. A quantity without enough data keeps the configured value.
struct TuneResult {
  double block_s = kNaN;                     // s, block length of the noise estimate
  std::uint64_t noise_block_pairs = 0;       // consecutive block pairs used
  bool noise_estimated = false;
  double noise_density_dps_rthz = kNaN;      // deg/s/sqrt(Hz), N
  std::uint64_t wander_pairs = 0;            // same-position visit pairs used
  bool q_estimated = false;
  double q_dps2_per_s = kNaN;                // (deg/s)^2/s, K^2 per axis
  bool q_upper_bound = false;                // the revisits showed no wander above the noise:
                                             // q_dps2_per_s is their one-sided 97.5 % upper bound,
                                             // applied (q_estimated) only when below the configured Q
  double sample_rate_hz = kNaN;              // Hz, used for N
};

/// Minimum counts before a quantity is trusted.
struct TuneLimits {
  double block_s = 0.5;                   // s, block of the noise estimate
  std::uint64_t min_noise_block_pairs = 10;
  std::uint64_t min_wander_pairs = 5;
};

/// The first pass: push every sample, then finish().
class NoiseTuner {
 public:
  /// `cfg`'s standstill settings and calibration and the box geometry decide where the
  /// standstills are and which matrices M form the residual.
  NoiseTuner(const EstimatorConfig& cfg, const BoxGeometry& box, const TuneLimits& limits = {});
  void push(const Sample& s);
  TuneResult finish();

 private:
  // the motion regressors of a block: fused body rate (deg/s) and specific force (m/s^2), box axes
  using Regressors = Eigen::Matrix<double, 6, 1>;
  struct Visit {
    double t_mid_s = kNaN;
    std::size_t n = 0;
    Eigen::Vector3d r_sum = Eigen::Vector3d::Zero();  // sum of n * block residual
    Regressors x_sum = Regressors::Zero();            // sum of n * block regressors
  };
  // per position pair: the weighted normal equations of r_a - r_b on x_a - x_b (w = 1 / (1/n_a + 1/n_b))
  struct MotionFit {
    Eigen::Matrix<double, 6, 6> xx = Eigen::Matrix<double, 6, 6>::Zero();
    // the pairs' noise covariance seen through dx, over 2 sigma^2: sum w dx dx^T less, for two
    // pairs that share a block (a standstill's consecutive pairs), w_a w_b / n_shared (dx_a dx_b^T
    // + dx_b dx_a^T): their dr have the shared block's mean with opposite signs
    Eigen::Matrix<double, 6, 6> xsx = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 3> xr = Eigen::Matrix<double, 6, 3>::Zero();
    double rr = 0.0;
    std::uint64_t pairs = 0;
    // after solve(): the fit is kept only when the motion explains more of the pairs' spread
    // than noise would (chi-square test at kMotionFitSignificance), else coef = 0 and ss = rr
    bool fitted = false;
    Eigen::Matrix<double, 6, 3> coef = Eigen::Matrix<double, 6, 3>::Zero();
    // Cov(coef column) / (2 sigma^2): the sandwich xx^+ xsx xx^+ (xx^+ the pseudo-inverse); a
    // smooth motion's consecutive pairs telescope, so this is far below xx^+ there
    Eigen::Matrix<double, 6, 6> coef_cov = Eigen::Matrix<double, 6, 6>::Zero();
    double ss = 0.0;    // weighted residual sum of squares after the fit
    double dof = 0.0;   // 3 (pairs - rank), or 3 pairs without a fit
    void solve();
  };
  void use_piece(const StandstillSegment& seg);
  Regressors regressors(const StandstillSegment& seg) const;
  void close_visit();

  TuneLimits limits_;
  double configured_q_dps2_per_s_;  // the Q a bound must be below to replace
  DriftlessFilter geometry_;  // only for its M_body_from_sensor (rotations or calibrated)
  StandstillDetector detector_;
  double last_t_s_ = kNaN;
  // the previous block of the current standstill
  bool have_block_ = false;
  double block_rest_s_ = kNaN;
  std::size_t block_n_ = 0;
  Eigen::Vector3d block_r_ = Eigen::Vector3d::Zero();
  Regressors block_x_ = Regressors::Zero();
  // the previous pair of the current standstill (it shares block_ with the next one)
  bool have_pair_ = false;
  double pair_w_ = 0.0;
  Regressors pair_dx_ = Regressors::Zero();
  std::map<std::pair<long, long>, MotionFit> motion_;  // per position pair (0.1 deg keys)
  std::uint64_t noise_pairs_ = 0;
  struct WanderPair {
    Eigen::Vector3d dr;
    Regressors dx;
    std::pair<long, long> key;
    // dt_s: between the visits' midpoints; window_s: (span_a + span_b) / 6, what averaging over the
    // two visits takes off a random walk's variance of their difference: q (dt_s - window_s)
    double dt_s, window_s, inv_n;
  };
  std::vector<WanderPair> wander_;
  // the standstill being collected, and the last visit per position pair (0.1 deg keys)
  Visit visit_;
  std::pair<long, long> visit_key_{0, 0};
  std::map<std::pair<long, long>, Visit> last_visit_;
  double rate_hz_ = kNaN;
};

/// Runs the first pass over `reader` (which it consumes).
TuneResult tune_from_log(log::LogReader& reader, const EstimatorConfig& cfg, const TuneLimits& limits = {});
/// Puts what was estimated into `cfg` (noise_density_dps_rthz, q_override_dps2_per_s; r_override
/// cleared) and leaves the rest.
void apply_tune(const TuneResult& t, EstimatorConfig& cfg);

}  // namespace driftless::est
