// BiasWhitener (the nuisance bias of a channel as a 2-state random process observed in white
// noise) against an explicit matrix Kalman filter and RTS smoother written from the textbook
// equations, and against the closed form of its constant-only case (a weighted mean).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Dense>

#include "diagnose/bias_filter.hpp"

namespace driftless::diagnose {
namespace {

// blocks of 0.1 s at 100 Hz with a gap and a few partial blocks
BlockSeries layout(std::size_t m) {
  BlockSeries b;
  b.sample_rate_hz = 100.0;
  for (std::size_t j = 0; j < m; ++j) {
    b.t_s.push_back(0.05 + 0.1 * static_cast<double>(j));
    std::uint16_t cnt = 10;
    if (j >= 40 && j < 55) cnt = 0;  // a flip: no data
    if (j % 17 == 3) cnt = 6;        // partial blocks
    b.count.push_back(cnt);
  }
  return b;
}

std::vector<double> series(std::size_t m, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<double> z(m);
  double walk = 0.3;
  for (std::size_t j = 0; j < m; ++j) {
    walk += 0.01 * n(rng);
    z[j] = walk + 0.02 * n(rng);
  }
  return z;
}

// the explicit filter: x = [constant + random walk, Gauss-Markov], F = diag(1, phi),
// Q = diag(K^2 dt, s^2 (1 - phi^2)), H = [1 1], R = N^2 fs / count; P0 = diag(sigma0^2, s^2)
struct Explicit {
  std::vector<double> nu, s, smooth;
  double neg2ll = 0.0;
  Eigen::Vector2d x_end;
  Eigen::Matrix2d p_end;
};
Explicit explicit_filter(const BlockSeries& b, const ChannelNoise& noise, const std::vector<double>& z) {
  const std::size_t m = z.size();
  Explicit out;
  out.nu.assign(m, 0.0);
  out.s.assign(m, 0.0);
  std::vector<Eigen::Vector2d> xf(m), xp(m);
  std::vector<Eigen::Matrix2d> pf(m), pp(m), F(m);
  Eigen::Vector2d x = Eigen::Vector2d::Zero();
  Eigen::Matrix2d P = Eigen::Vector2d(noise.turn_on_sigma_dps * noise.turn_on_sigma_dps, noise.gm_sigma_dps * noise.gm_sigma_dps).asDiagonal();
  const Eigen::RowVector2d H(1.0, 1.0);
  bool first = true;
  for (std::size_t j = 0; j < m; ++j) {
    const double dt = j == 0 ? 0.0 : b.t_s[j] - b.t_s[j - 1];
    const double phi = std::exp(-dt / noise.gm_tau_s);
    F[j] = Eigen::Vector2d(1.0, phi).asDiagonal();
    const Eigen::Matrix2d Q = Eigen::Vector2d(noise.rrw_dps_rts * noise.rrw_dps_rts * dt,
                                              noise.gm_sigma_dps * noise.gm_sigma_dps * (1.0 - phi * phi)).asDiagonal();
    x = F[j] * x;
    P = F[j] * P * F[j].transpose() + Q;
    xp[j] = x, pp[j] = P;
    if (b.count[j] > 0) {
      const double r = noise.white_dps_rthz * noise.white_dps_rthz * b.sample_rate_hz / b.count[j];
      const double nu = z[j] - H * x;
      const double s = (H * P * H.transpose())(0, 0) + r;
      const Eigen::Vector2d K = P * H.transpose() / s;
      x += K * nu;
      P = (Eigen::Matrix2d::Identity() - K * H) * P;
      if (!first) {  // the first observed block only fixes the turn-on bias (diffuse prior)
        out.nu[j] = nu, out.s[j] = s;
        out.neg2ll += std::log(s) + nu * nu / s;
      }
      first = false;
    }
    xf[j] = x, pf[j] = P;
  }
  out.x_end = x, out.p_end = P;
  // Rauch-Tung-Striebel: xs_j = xf_j + C (xs_{j+1} - xp_{j+1}), C = Pf F' Pp^-1
  out.smooth.assign(m, 0.0);
  Eigen::Vector2d xs = xf[m - 1];
  out.smooth[m - 1] = xs.sum();
  for (std::size_t j = m - 1; j-- > 0;) {
    const Eigen::Matrix2d C = pf[j] * F[j + 1].transpose() * pp[j + 1].inverse();
    xs = xf[j] + C * (xs - xp[j + 1]);
    out.smooth[j] = xs.sum();
  }
  return out;
}

TEST(BiasWhitener, MatchesAnExplicitKalmanFilterAndSmoother) {
  // GIVEN a block series with gaps and partial blocks and a noise model with every process
  const BlockSeries b = layout(300);
  ChannelNoise noise;
  noise.white_dps_rthz = 0.006;
  noise.gm_sigma_dps = 0.05;
  noise.gm_tau_s = 7.0;
  noise.rrw_dps_rts = 0.02;
  noise.turn_on_sigma_dps = 30.0;
  const std::vector<double> z = series(b.t_s.size(), 5);
  // WHEN whitened, scored and smoothed
  const BiasWhitener w(b, noise);
  std::vector<double> white(z.size());
  w.whiten(z, white);
  const Explicit e = explicit_filter(b, noise, z);
  // THEN every innovation, the likelihood, the smoothed bias and the final sigma agree to 1e-9
  for (std::size_t j = 0; j < z.size(); ++j) {
    const double want = e.s[j] > 0 ? e.nu[j] / std::sqrt(e.s[j]) : 0.0;
    EXPECT_NEAR(white[j], want, 1e-9 * (1.0 + std::abs(want))) << j;
    EXPECT_EQ(w.used()[j] != 0, e.s[j] > 0) << j;
  }
  EXPECT_NEAR(w.neg2_loglik(z), e.neg2ll, 1e-9 * std::abs(e.neg2ll));
  // the one-pass form (no stored gains) does the same arithmetic: the same bits
  EXPECT_EQ(BiasWhitener::neg2_loglik(b, noise, z), w.neg2_loglik(z));
  const std::vector<double> sm = w.smooth(z);
  for (std::size_t j = 0; j < z.size(); ++j) EXPECT_NEAR(sm[j], e.smooth[j], 1e-9) << j;
  EXPECT_NEAR(w.final_bias_sigma_dps(), std::sqrt(e.p_end(0, 0)), 1e-12);
}

TEST(BiasWhitener, WhitenedGramIsTheGramOfTheWhitenedColumns) {
  // GIVEN three regressor columns and a residual on a layout with a gap and partial blocks
  const BlockSeries b = layout(700);  // more blocks than one chunk of the one-pass sum
  ChannelNoise noise;
  noise.white_dps_rthz = 0.006;
  noise.gm_sigma_dps = 0.05;
  noise.gm_tau_s = 7.0;
  noise.rrw_dps_rts = 0.02;
  const std::size_t m = b.t_s.size();
  Eigen::MatrixXf X(static_cast<Eigen::Index>(m), 3);
  for (int i = 0; i < 3; ++i) {
    const std::vector<double> x = series(m, 11 + static_cast<unsigned>(i));
    for (std::size_t j = 0; j < m; ++j) X(static_cast<Eigen::Index>(j), i) = static_cast<float>(x[j]);
  }
  const std::vector<double> z = series(m, 5);
  // WHEN the Gram is formed in one pass, in float and in double columns
  const WhitenedGram g = BiasWhitener::whitened_gram(b, noise, X, z);
  const WhitenedGram gd = BiasWhitener::whitened_gram(b, noise, Eigen::MatrixXd(X.cast<double>()), z);
  // THEN it is A'A of the columns whitened one by one (to 1e-12 of its scale), over the used blocks
  const BiasWhitener w(b, noise);
  Eigen::MatrixXd A(static_cast<Eigen::Index>(m), 4);
  std::vector<double> col(m), out(m);
  for (int i = 0; i < 4; ++i) {
    for (std::size_t j = 0; j < m; ++j) col[j] = i < 3 ? static_cast<double>(X(static_cast<Eigen::Index>(j), i)) : z[j];
    w.whiten(col, out);
    for (std::size_t j = 0; j < m; ++j) A(static_cast<Eigen::Index>(j), i) = out[j];
  }
  const Eigen::MatrixXd want = A.transpose() * A;
  EXPECT_EQ(g.used, w.used_count());
  ASSERT_EQ(g.gram.rows(), 4);
  EXPECT_LT((g.gram - want).cwiseAbs().maxCoeff(), 1e-12 * want.cwiseAbs().maxCoeff());
  EXPECT_LT((gd.gram - want).cwiseAbs().maxCoeff(), 1e-12 * want.cwiseAbs().maxCoeff());
}

TEST(BiasWhitener, ConstantBiasIsTheWeightedMean) {
  // GIVEN only a constant bias (no drift) with prior sigma0 in white noise
  const BlockSeries b = layout(120);
  ChannelNoise noise;
  noise.white_dps_rthz = 0.01;
  noise.turn_on_sigma_dps = 2.0;
  const std::vector<double> z = series(b.t_s.size(), 9);
  // THEN the smoothed bias is constant and equals the closed-form posterior mean
  // (sum c_j z_j / r_1) / (1/sigma0^2 + sum c_j / r_1), r_1 = N^2 fs (one sample), and the
  // posterior sigma is the square root of the inverse of that denominator
  const double r1 = noise.white_dps_rthz * noise.white_dps_rthz * b.sample_rate_hz;
  double num = 0.0, den = 1.0 / (noise.turn_on_sigma_dps * noise.turn_on_sigma_dps);
  for (std::size_t j = 0; j < z.size(); ++j) {
    num += b.count[j] * z[j] / r1;
    den += b.count[j] / r1;
  }
  const BiasWhitener w(b, noise);
  const std::vector<double> sm = w.smooth(z);
  for (double v : sm) EXPECT_NEAR(v, num / den, 1e-12);
  EXPECT_NEAR(w.final_bias_sigma_dps(), std::sqrt(1.0 / den), 1e-15);
}

TEST(BiasWhitener, WhitenedNoiseIsStandardNormal) {
  // GIVEN samples drawn from exactly the model (white + random walk), THEN the whitened
  // innovations have unit variance (chi-square bound on 2000 blocks, seeded) and no lag-1 correlation
  BlockSeries b;
  b.sample_rate_hz = 100.0;
  ChannelNoise noise;
  noise.white_dps_rthz = 0.005;
  noise.rrw_dps_rts = 0.01;
  std::mt19937_64 rng(21);
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<double> z;
  double bias = 1.7;
  const std::size_t m = 2000;
  for (std::size_t j = 0; j < m; ++j) {
    b.t_s.push_back(0.1 * static_cast<double>(j));
    b.count.push_back(10);
    if (j > 0) bias += noise.rrw_dps_rts * std::sqrt(0.1) * n(rng);
    z.push_back(bias + noise.white_dps_rthz * std::sqrt(b.sample_rate_hz / 10.0) * n(rng));
  }
  const BiasWhitener w(b, noise);
  std::vector<double> white(m);
  w.whiten(z, white);
  double s2 = 0.0, s11 = 0.0;
  for (std::size_t j = 2; j < m; ++j) s2 += white[j] * white[j], s11 += white[j] * white[j - 1];
  const double var = s2 / static_cast<double>(m - 2);
  // chi-square on 1998 dof: 99.9 % bounds are about 1 +- 3.29 sqrt(2/1998)
  EXPECT_NEAR(var, 1.0, 3.29 * std::sqrt(2.0 / 1998.0));
  EXPECT_LT(std::abs(s11 / s2), 3.29 / std::sqrt(1998.0));
}

}  // namespace
}  // namespace driftless::diagnose
