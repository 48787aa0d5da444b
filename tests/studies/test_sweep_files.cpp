// Every shipped sweep file (models/sweeps/*.yaml) parses, expands and builds its first run's
// scenario and filter configuration (keys that do not exist in the scenario schema fail here).
#include <filesystem>

#include <gtest/gtest.h>

#include "twin/sensor/sensor_model.hpp"
#include "studies/jobs.hpp"
#include "studies/sweep.hpp"

namespace driftless::studies {

using twin::SensorParams;
namespace {

TEST(SweepFiles, EveryShippedFileBuildsItsRuns) {
  int files = 0;
  for (const auto& e : std::filesystem::directory_iterator(std::string(DRIFTLESS_SOURCE_DIR) + "/models/sweeps")) {
    if (e.path().extension() != ".yaml") continue;
    ++files;
    SCOPED_TRACE(e.path().string());
    const SweepConfig c = load_sweep(e.path());
    const auto specs = expand(c);
    ASSERT_EQ(specs.size(), c.runs());
    const SetupBuilder builder(c);
    // first and last run: every grid value of the extremes applies cleanly
    for (const auto* s : {&specs.front(), &specs.back()}) {
      const RunSetup setup = builder.build(*s);
      EXPECT_EQ(setup.scenario.seed, s->seed);
      if (c.duration_s > 0) {
        EXPECT_EQ(setup.scenario.duration_s, c.duration_s);
      }
    }
  }
  EXPECT_GE(files, 10);
}

// a grid value reaches the scenario and the filter
TEST(SweepFiles, GridValuesReachScenarioAndFilter) {
  const SweepConfig c = parse_sweep(R"(
runner: fast
scenario: default
grid:
  nd: {set: [model.sensor1.effects.white_noise.density_dps_rthz, estimator.noise_density_dps_rthz], vector3: true, values: [0.02]}
  angle: {set: flip_schedule.flip_angle_deg, values: [45]}
  on: {set: model.sensor2.effects.adc_missing_codes.enabled, boolean: true, values: [1]}
)", "t.yaml", ".");
  const RunSetup s = SetupBuilder(c).build(expand(c)[0]);
  EXPECT_EQ(s.estimator.noise_density_dps_rthz, 0.02);
  EXPECT_EQ(s.scenario.flip_schedule.flip_angle_deg, 45.0);
  const SensorParams& p2 = s.scenario.model.sensor2;
  EXPECT_TRUE(p2.adc_missing_codes.enabled);
  const SensorParams& p1 = s.scenario.model.sensor1;
  EXPECT_EQ(p1.white_noise.density_dps_rthz, Eigen::Vector3d::Constant(0.02));
  EXPECT_THROW(SetupBuilder(parse_sweep("grid: {x: {set: fault.bogus, values: [1]}}\n", "u.yaml", "."))
                   .build(RunSpec{0, 0, 0, 1, {1.0}}),
               std::invalid_argument);
}

}  // namespace
}  // namespace driftless::studies
