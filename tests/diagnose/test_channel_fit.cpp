// The channel fit's white density: its maximum likelihood against the closed form of the
// constant-only case, wherever the robust first guess lands.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "diagnose/channel_fit.hpp"

namespace driftless::diagnose {
namespace {

TEST(WhiteDensity, IsTheMaximumLikelihoodEvenFarFromTheRobustGuess) {
  // GIVEN block means of 0.1 s at 100 Hz (10 samples each) of a slow sine of amplitude 1 deg/s
  // and period 200 blocks plus white noise of 1e-3 deg/s, and a noise model of white noise and
  // a diffuse constant bias only (no drift processes to absorb the sine)
  const std::size_t m = 2000, L = 10;
  BlockSeries blocks;
  blocks.sample_rate_hz = 100.0;
  std::mt19937 g(12);
  std::normal_distribution<double> n(0.0, 1e-3);
  std::vector<double> z(m);
  for (std::size_t j = 0; j < m; ++j) {
    blocks.t_s.push_back(0.05 + 0.1 * static_cast<double>(j));
    blocks.count.push_back(static_cast<std::uint16_t>(L));
    z[j] = std::sin(2.0 * M_PI * static_cast<double>(j) / 200.0) + n(g);
  }
  ChannelData c;
  c.noise.white_dps_rthz = 0.005;
  c.noise.gm_sigma_dps = 0.0;
  c.noise.rrw_dps_rts = 0.0;
  c.noise.turn_on_sigma_dps = 1e3;
  // WHEN the white density is fitted (its robust guess, from the block differences' median, is
  // ~e^-3.4 of the likelihood's: the sine hardly moves from block to block)
  const double N = fit_white_density(c, blocks, z);
  // THEN it is the closed form: the block mean's variance N^2 fs / L is the residual variance
  // about the mean over m - 1 (the diffuse first block left out); capped at the guess's e^2
  // (the bracket before) it was about 76 % low
  double mean = 0.0;
  for (double v : z) mean += v / static_cast<double>(m);
  double ss = 0.0;
  for (double v : z) ss += (v - mean) * (v - mean);
  const double want = std::sqrt(ss / static_cast<double>(m - 1) * static_cast<double>(L) / blocks.sample_rate_hz);
  EXPECT_NEAR(N / want, 1.0, 2e-3) << "N " << N << " want " << want;
}

}  // namespace
}  // namespace driftless::diagnose
