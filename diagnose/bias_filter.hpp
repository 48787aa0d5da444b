// The nuisance bias of one gyro channel as a random process (turn-on constant + random walk +
// first-order Gauss-Markov) observed in white noise, on block means of the residual.
// A forward Kalman filter whitens any column (innovations / sqrt(s)): generalised least squares
// of a residual on regressors is then ordinary least squares on whitened columns, and the
// filter's innovations give the exact Gaussian log-likelihood (docs/compare.md).
#pragma once

#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include <Eigen/Core>

namespace driftless::diagnose {

/// Noise model of one channel. Units: deg/s, s.
struct ChannelNoise {
  double white_dps_rthz = 0.005;   // N, angle random walk density, deg/s/sqrt(Hz)
  double gm_sigma_dps = 0.0;       // bias instability: Gauss-Markov steady-state sigma, deg/s
  double gm_tau_s = 100.0;         // its correlation time, s
  double rrw_dps_rts = 0.0;        // K, rate random walk, deg/s/sqrt(s)
  double turn_on_sigma_dps = 1e3;  // prior sigma of the constant (turn-on) bias, deg/s (diffuse)
  /// Throws std::invalid_argument naming the field on a bad value.
  void validate() const;
};

/// Block layout: block j holds count[j] samples (0 = missing) at time t_s[j].
struct BlockSeries {
  std::vector<double> t_s;           // s, block centre times
  std::vector<std::uint16_t> count;  // samples averaged in each block (0 = no data)
  double sample_rate_hz = 100.0;     // Hz, of the samples inside the blocks
};

/// The whitened Gram matrix of columns [X, z] and how many blocks entered it.
struct WhitenedGram {
  Eigen::MatrixXd gram;   // (P+1) x (P+1): whitened [X z]' [X z]
  std::size_t used = 0;   // blocks that enter fits (used_count())
};

/// Precomputed gains of the whitening filter for one noise model and block layout.
class BiasWhitener {
 public:
  BiasWhitener(const BlockSeries& blocks, const ChannelNoise& noise);
  /// Whitened innovations of `z` (block means): out[j] = nu_j / sqrt(s_j), 0 where excluded.
  void whiten(std::span<const double> z, std::span<double> out) const;
  /// -2 log-likelihood of z under the model (the diffuse first block left out).
  double neg2_loglik(std::span<const double> z) const;
  /// The same -2 log-likelihood in one pass that keeps no gains: for the noise-model searches,
  /// which evaluate many noise models once each (no per-block storage, identical arithmetic).
  static double neg2_loglik(const BlockSeries& blocks, const ChannelNoise& noise, std::span<const double> z);
  /// The Gram matrix of whiten() applied to every column of `cols` (blocks x P) and to `z`, in
  /// one pass that keeps nothing per block (the rebuild after every noise-model change).
  static WhitenedGram whitened_gram(const BlockSeries& blocks, const ChannelNoise& noise,
                                    const Eigen::MatrixXf& cols, std::span<const double> z);
  static WhitenedGram whitened_gram(const BlockSeries& blocks, const ChannelNoise& noise,
                                    const Eigen::MatrixXd& cols, std::span<const double> z);
  /// Smoothed bias (RTS) given z: the nuisance estimate, deg/s, per block.
  std::vector<double> smooth(std::span<const double> z) const;
  /// Which blocks enter fits (data present, not the diffuse first one).
  const std::vector<std::uint8_t>& used() const { return used_; }
  std::size_t used_count() const { return n_used_; }
  /// Posterior sigma of the constant (random-walk) state at the end, deg/s.
  double final_bias_sigma_dps() const { return final_sigma_; }

 private:
  struct Step {
    double phi;         // GM transition
    double q_rw, q_gm;  // process noise variances
    double k0, k1;      // Kalman gain for the two states (0 when no data)
    double s;           // innovation variance
    // RTS smoother: filtered and predicted covariances
    double pf00, pf01, pf11, pp00, pp01, pp11;
  };
  /// The covariance recursion over the blocks, shared by the constructor and the one-pass
  /// functions: calls visit(j, step, used) after block j.
  template <class Visit>
  static void recursion(const BlockSeries& blocks, const ChannelNoise& noise, Visit&& visit);
  template <class Matrix>
  static WhitenedGram whitened_gram_of(const BlockSeries& blocks, const ChannelNoise& noise,
                                       const Matrix& cols, std::span<const double> z);
  /// The filter's forward pass over z, the one loop whiten, neg2_loglik and smooth share: after
  /// block j it calls visit(j, step, nu, x0, x1) with the innovation nu (NaN where the block has
  /// no data and the state was only predicted) and the filtered states.
  template <class Visit>
  void forward(std::span<const double> z, Visit&& visit) const {
    double x0 = 0.0, x1 = 0.0;
    for (std::size_t j = 0; j < steps_.size(); ++j) {
      const Step& st = steps_[j];
      x1 *= st.phi;
      double nu = std::numeric_limits<double>::quiet_NaN();
      if (st.s > 0.0) {
        nu = z[j] - x0 - x1;
        x0 += st.k0 * nu;
        x1 += st.k1 * nu;
      }
      visit(j, st, nu, x0, x1);
    }
  }
  std::vector<Step> steps_;
  std::vector<std::uint8_t> used_;
  std::size_t n_used_ = 0;
  double final_sigma_ = 0.0;
};

/// Block means of a per-sample series over the blocks (NaN or masked samples skipped).
void block_means(std::span<const double> x, std::span<const std::uint8_t> mask,
                 std::size_t block_len, std::span<double> out);

}  // namespace driftless::diagnose
