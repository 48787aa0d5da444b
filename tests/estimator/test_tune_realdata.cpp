// --tune auto on noise we did not make: a real MPU6050's static recording (../shared/realdata,
// tomisuarez2, 449 s at 100 Hz, raw counts, DLPF off, quantised in 1/131 deg/s) with its mean
// removed supplies the noise of both gyros of a synthetic flipping box (first and second half of
// the recording). The tuner's noise density must match the recording's own Allan deviation at the
// tuner's block length, and the tuned filter must be healthy.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "estimator/pipeline.hpp"
#include "estimator/tune.hpp"
#include "tests/estimator/synth.hpp"
#include "tests/temp_path.hpp"

namespace driftless::est {
namespace {

const std::filesystem::path kFile = std::filesystem::path(DRIFTLESS_SOURCE_DIR) / ".." / "shared" / "realdata" /
                                    "mpu6050-tomisuarez2" / "example_data_tinit_calc.csv";
constexpr double kLsbPerDps = 131.0;  // the recording's gyro scale (its README)

// gyro columns in deg/s, mean removed
std::vector<Eigen::Vector3d> load_noise() {
  std::ifstream f(kFile);
  std::string line;
  while (std::getline(f, line) && line.rfind("ax,", 0) != 0) {
  }
  std::vector<Eigen::Vector3d> g;
  while (std::getline(f, line)) {
    std::stringstream ss(line);
    double v[6];
    char comma;
    bool ok = true;
    for (int i = 0; i < 6; ++i) {
      ok = ok && static_cast<bool>(ss >> v[i]);
      if (i < 5) ss >> comma;
    }
    if (ok) g.emplace_back(v[3] / kLsbPerDps, v[4] / kLsbPerDps, v[5] / kLsbPerDps);
  }
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& x : g) mean += x;
  mean /= double(g.size());
  for (auto& x : g) x -= mean;
  return g;
}

// N from the non-overlapping Allan variance at tau = m / rate: N^2 = AVAR(tau) tau (white noise)
double allan_density(const std::vector<Eigen::Vector3d>& g, std::size_t m, double rate_hz) {
  double sum = 0.0;
  std::size_t n = 0;
  for (int axis = 0; axis < 3; ++axis) {
    double prev = kNaN;
    for (std::size_t k = 0; k + m <= g.size(); k += m) {
      double mean = 0.0;
      for (std::size_t j = k; j < k + m; ++j) mean += g[j][axis];
      mean /= double(m);
      if (std::isfinite(prev)) {
        sum += 0.5 * (mean - prev) * (mean - prev);
        ++n;
      }
      prev = mean;
    }
  }
  return std::sqrt(sum / double(n) * double(m) / rate_hz);
}

TEST(TuneRealData, NoiseDensityOfARealMpu6050AndAHealthyTunedFilter) {
  // GIVEN the real recording's noise on both gyros of a 220 s flipping-box log (no other noise)
  if (!std::filesystem::exists(kFile)) GTEST_SKIP() << "no " << kFile;
  const auto noise = load_noise();
  ASSERT_GT(noise.size(), 44000u);
  const std::size_t half = noise.size() / 2;
  test::SynthParams p;
  p.rate_hz = 100.0;
  p.duration_s = double(half) / p.rate_hz - 1.0;
  p.extra_noise_dps = [&](int sensor, std::size_t k) { return noise[(sensor == 1 ? 0 : half) + k]; };
  const auto path = test::temp_path("real_noise.csv");
  test::synth_log(p, path);
  // WHEN the first pass measures it
  EstimatorConfig cfg;
  log::LogReader first(path);
  const TuneResult t = tune_from_log(first, cfg);
  // THEN its N is the recording's own Allan density at 0.5 s within 8 % (about 1300 block pairs:
  // 3 % standard error; the recording is not exactly white)
  const double n_allan = allan_density(noise, 50, p.rate_hz);
  ASSERT_TRUE(t.noise_estimated);
  EXPECT_NEAR(t.noise_density_dps_rthz, n_allan, 0.08 * n_allan) << "Allan " << n_allan;
  std::printf("real MPU6050 noise: N from --tune auto %.5f, from the recording's Allan deviation %.5f "
              "deg/s/sqrt(Hz)\n", t.noise_density_dps_rthz, n_allan);
  EXPECT_GT(t.noise_density_dps_rthz, 1.5 * cfg.noise_density_dps_rthz);  // this chip is noisier than the spec
  // AND the filter with it locks, rejects nothing and keeps its NIS mean at or below the band's top
  apply_tune(t, cfg);
  log::LogReader second(path);
  const auto s = run_estimate(second, cfg, nullptr);
  EXPECT_NE(s.health.verdict, HealthVerdict::kFailed);
  EXPECT_TRUE(s.health.locked);
  EXPECT_EQ(s.health.rejected, 0u);
  EXPECT_LT(s.health.nis_mean, s.health.nis_mean_band_hi);
  EXPECT_GE(s.truth.within_3sigma_fraction, 0.95);
  std::printf("tuned: %s, NIS mean %.2f (band %.2f..%.2f), %.1f %% within 3 sigma\n", to_string(s.health.verdict),
              s.health.nis_mean, s.health.nis_mean_band_lo, s.health.nis_mean_band_hi,
              100.0 * s.truth.within_3sigma_fraction);
}

}  // namespace
}  // namespace driftless::est
