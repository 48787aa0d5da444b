// The self-calibrating filter's standstill updates on the built-in `static` scenario (MPU6050
// defaults, uncalibrated: g-sensitivity, scale, misalignment, temperature; `estimate --selfcal
// --box-at-rest`) are consistent: their NIS, pooled over seeds, lies in its chi-square band
// (docs/results.md, the `static` section). Before stop 29 it sat below the band (3.64 of 4 over 16
// seeds of 1 h, the sigma about 5 % large): the scale/misalignment rows took the box rate from the
// bias alone, so sensor 2's observed G f (~0.06 deg/s) was read as a box rate, and added to R the
// rate's error as E times the *bias* sigma, which on a vertical hinge keeps the G prior (0.058 deg/s)
// although the correction b + G f that sets the rate is known to 0.005 (docs/estimator.md 1c).
// Seeded: 16 x 1 h of the twin, ~10 s.
#include <cstdint>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "estimator/box_geometry.hpp"
#include "estimator/filter.hpp"
#include "estimator/stats.hpp"
#include "twin/simulator.hpp"

namespace driftless::twin {
namespace {

constexpr int kStaticNisSeeds = 16;
constexpr double kStaticNisDurationS = 3600.0;
// s: the standstill updates scored start after the lock (156.5 s on every seed: the correction
// sigma below 0.05 deg/s) and the first two cycles of the four positions
constexpr double kStaticNisFromS = 300.0;

struct StaticNisPool {
  double nis = 0.0, dof = 0.0;
  int updates = 0, rejected = 0;
};

void run_static_nis_seed(std::uint64_t seed, StaticNisPool& pool) {
  Scenario sc = load_scenario("static");
  sc.seed = seed;
  sc.duration_s = kStaticNisDurationS;
  Simulator sim(sc);
  est::EstimatorConfig cfg;  // the defaults, as `estimate --selfcal --box-at-rest` with no --config
  cfg.self_calibration = true;
  cfg.box_at_rest = true;
  est::DriftlessFilter f(cfg, est::box_geometry_from_metadata(sim.metadata()));
  Sample s;
  while (sim.next(s)) {
    const est::PushStatus st = f.push(s);
    if ((st != est::PushStatus::kUpdated && st != est::PushStatus::kRejected) || s.t_s < kStaticNisFromS) continue;
    const est::UpdateRecord& u = f.last_update();
    if (!u.accepted) {
      ++pool.rejected;
      continue;
    }
    pool.nis += u.nis;
    pool.dof += u.dim;
    ++pool.updates;
  }
}

// GIVEN the built-in `static` scenario, seeds 1-16 of 1 h (docs/results.md's seeds)
// WHEN the self-calibrating filter runs with box_at_rest (4-dim standstill updates: eq. (2)'s
// residual and the vertical Earth rate)
// THEN no update is rejected and the pooled NIS per dof lies in its 99.9 % chi-square band
// (0.944-1.058 for the 1664 updates of 4 dof); stop 28's filter read 0.914 (below), this one 0.966
TEST(SelfcalConsistency, StaticBoxAtRestStandstillNisIsInItsBand) {
  StaticNisPool pool;
  for (int i = 1; i <= kStaticNisSeeds; ++i) run_static_nis_seed(static_cast<std::uint64_t>(i), pool);
  const double lo = est::chi2_quantile(0.0005, pool.dof) / pool.dof;
  const double hi = est::chi2_quantile(0.9995, pool.dof) / pool.dof;
  std::printf("[ info ] static --selfcal --box-at-rest, %d seeds x 1 h: %d standstill updates after %.0f s, "
              "NIS per dof %.4f (99.9 %% band %.4f..%.4f), %d rejected\n",
              kStaticNisSeeds, pool.updates, kStaticNisFromS, pool.nis / pool.dof, lo, hi, pool.rejected);
  ASSERT_GT(pool.updates, 1500);
  EXPECT_EQ(pool.rejected, 0);
  EXPECT_GT(pool.nis / pool.dof, lo);
  EXPECT_LT(pool.nis / pool.dof, hi);
}

}  // namespace
}  // namespace driftless::twin
