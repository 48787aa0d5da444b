// Fault detection on a moving base (the box on the pan/tilt unit, up to 50 deg/s; fast path with
// the real DriftLess filter and the MPU6050 noise chain, DLPF included).
// GIVEN fault-free runs WHEN 120 fresh seeds x 30 min (60 h of moving-base monitoring) run THEN no
// alarm: with 0 alarms in 60 h the 95 % upper bound on the rate is 3 / 60 h = 0.05 per hour, the
// design rate stated in docs/fdi.md (before the long-run noise scale, this set raised alarms at
// about 0.05 per hour: 5 in 100 h).
// GIVEN each fault planted on each sensor axis at t = 600 s WHEN the run goes on THEN it is
// detected and classified within the stated delays (docs/fdi.md).
#include <gtest/gtest.h>

#include "studies/jobs.hpp"
#include "studies/sweep.hpp"

namespace driftless::studies {
namespace {

double metric(const RunResult& r, const std::string& k) {
  for (const auto& [n, v] : r.metrics) {
    if (n == k) return v;
  }
  ADD_FAILURE() << "no metric " << k;
  return 0;
}

SweepConfig moving_sweep() {
  return load_sweep(std::string(DRIFTLESS_SOURCE_DIR) + "/models/sweeps/fdi_moving.yaml");
}

std::vector<RunResult> run_all(const SweepConfig& c, std::vector<RunSpec>* specs) {
  *specs = expand(c);
  std::vector<std::size_t> idx(specs->size());
  for (std::size_t i = 0; i < idx.size(); ++i) idx[i] = i;
  return run_parallel(*specs, idx, make_job(c), 2);
}

TEST(FdiMoving, FalseAlarmRateWithinDesign) {
  SweepConfig c = moving_sweep();
  c.grid.clear();        // fault.kind defaults to 0: no fault
  c.monte_carlo = 120;
  c.duration_s = 1800;
  c.seed = 20261121;     // not the seeds of fdi_moving.yaml or docs/results.md
  std::vector<RunSpec> specs;
  const auto results = run_all(c, &specs);
  int alarms = 0;
  for (const auto& r : results) {
    ASSERT_TRUE(r.ok) << r.error;
    if (metric(r, "false_alarm") != 0.0) {
      ++alarms;
      ADD_FAILURE() << "false alarm in run " << r.index << " (seed " << specs[r.index].seed << ")";
    }
  }
  const double hours = c.monte_carlo * c.duration_s / 3600.0;
  EXPECT_EQ(alarms, 0) << alarms << " alarms in " << hours << " h";
}

TEST(FdiMoving, PlantedFaultsDetectedAndClassified) {
  SweepConfig c = moving_sweep();
  c.monte_carlo = 1;
  c.duration_s = 700;
  ASSERT_EQ(c.grid[0].name, "fault_kind");
  std::vector<RunSpec> specs;
  const auto results = run_all(c, &specs);
  int scale_runs = 0, scale_kind_correct = 0;
  for (std::size_t i = 0; i < results.size(); ++i) {
    const RunResult& r = results[i];
    ASSERT_TRUE(r.ok) << r.error;
    const int kind = static_cast<int>(specs[i].values[0]);
    SCOPED_TRACE(::testing::Message() << "run " << i << " kind " << kind << " sensor "
                                      << specs[i].values[1] << " axis " << specs[i].values[2]);
    EXPECT_EQ(metric(r, "false_alarm"), 0.0);
    if (kind == 0) continue;
    EXPECT_EQ(metric(r, "detected"), 1.0);
    // stated delays under motion (docs/fdi.md): bias step and noise alarm 0.5 s, scale 3 s;
    // isolation: bias step within two flips (50 s), noise 5 s, scale up to 9 s (the pan/tilt
    // unit dwells at rest up to 5 s, when a scale change is invisible)
    EXPECT_LE(metric(r, "alarm_delay_s"), kind == 4 ? 3.0 : 0.5);
    EXPECT_LE(metric(r, "isolation_delay_s"), kind == 2 ? 50.0 : kind == 4 ? 9.0 : 5.0);
    if (kind == 4) {
      // a scale change under motion is sometimes read as a bias step (docs/fdi.md: 2 of 24)
      ++scale_runs;
      scale_kind_correct += metric(r, "kind_correct") == 1.0;
      continue;
    }
    EXPECT_EQ(metric(r, "kind_correct"), 1.0);
    // a scale change's sensor is ambiguous by nature (docs/fdi.md): sensor and axis only for
    // steps and bursts
    EXPECT_EQ(metric(r, "sensor_correct"), 1.0);
    EXPECT_EQ(metric(r, "axis_correct"), 1.0);
  }
  // six scale changes: with the documented rate of 1 in 12 read as a bias step, two or more
  // misreadings happen in 8 % of seeds and three or more in 1 %: allow two
  EXPECT_EQ(scale_runs, 6);
  EXPECT_GE(scale_kind_correct, scale_runs - 2);
}

}  // namespace
}  // namespace driftless::studies
