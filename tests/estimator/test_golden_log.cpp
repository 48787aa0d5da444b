// The golden log (tests/data/estimator_golden/log.csv) is the synthetic generator's output for a
// fixed seed: regenerating it must give the same bytes. tests/cli/estimate_golden.sh checks the
// estimator output on it against the committed estimate.csv.
// To change it on purpose: DRIFTLESS_UPDATE_GOLDEN=1 ./estimator_test_golden_log
#include <cstdlib>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "tests/estimator/synth.hpp"

#include "tests/temp_path.hpp"

namespace driftless::test {
namespace {

SynthParams golden_params() {
  SynthParams p;
  p.rate_hz = 10.0;
  p.duration_s = 120.0;
  p.standstill_s = 8.0;
  p.flip_s = 1.0;
  p.noise_sigma_dps = 0.005 * std::sqrt(p.rate_hz);
  p.gm_sigma_dps = 0.02;
  p.gm_tau_s = 300.0;
  p.seed = 20240601;
  p.body_rate_dps = [](double t) { return Eigen::Vector3d(4.0 * std::sin(0.2 * t), 2.0 * std::cos(0.13 * t), 1.5); };
  return p;
}

std::string slurp(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

TEST(GoldenLogTest, RegeneratingTheGoldenLogGivesTheSameBytes) {
  const std::filesystem::path committed =
      std::filesystem::path(DRIFTLESS_SOURCE_DIR) / "tests/data/estimator_golden/log.csv";
  if (std::getenv("DRIFTLESS_UPDATE_GOLDEN") != nullptr) synth_log(golden_params(), committed);
  const auto fresh = test::temp_path("driftless_golden_log.csv");
  synth_log(golden_params(), fresh);
  ASSERT_TRUE(std::filesystem::exists(committed)) << committed;
  EXPECT_EQ(slurp(fresh), slurp(committed)) << "the synthetic generator changed; update on purpose "
                                               "with DRIFTLESS_UPDATE_GOLDEN=1";
}

}  // namespace
}  // namespace driftless::test
