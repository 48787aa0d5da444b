// The same seed is the same sensor unit everywhere: the calibration rig and the simulator draw
// each sensor's run-to-run spread from the one named stream (estimator/random.hpp), so a unit
// calibrated with `driftless calibrate` is the unit `driftless simulate` runs.
#include <cmath>

#include <gtest/gtest.h>

#include "calibration/rig_sim.hpp"
#include "estimator/geometry.hpp"
#include "twin/scenario.hpp"
#include "twin/simulator.hpp"

namespace driftless::calib {
namespace {

// C = misalignment diag(scale) R_sensor_from_nominal of a realised unit (temperature left out)
Eigen::Matrix3d unit_calibration(const twin::SensorInstance& inst) {
  return inst.misalignment * inst.scale.asDiagonal() * inst.R_sensor_from_nominal;
}

TEST(SeedStreams, CalibrateAndSimulateDrawTheSameUnitFromOneSeed) {
  // GIVEN a short rig run with the MPU6050's run-to-run spread of scale, cross-axis and mounting
  CalibScenario cs;
  cs.scenario = twin::parse_scenario(R"(
name: seed-streams
seed: 11
latitude_deg: 52.0
sample_rate_hz: 100
platform_readback: end_stops
model:
  sensor1: {preset: mpu6050, effects: {temperature: {enabled: false}, g_sensitivity: {enabled: false}}}
  sensor2: {preset: mpu6050, effects: {temperature: {enabled: false}, g_sensitivity: {enabled: false}}}
motion: {type: static}
)", "seed-streams.yaml", ".");
  cs.rig.procedure.segment_s = 4.0;
  cs.rig.procedure.orientations = {"XY"};
  cs.rig.procedure.gap_s = 8.0;
  // WHEN the rig runs and the simulator is built from the same scenario (same seed)
  const RigRun run = run_rig(cs);
  const twin::Simulator sim(cs.scenario);
  // THEN the rig's true M is the simulator's unit behind the rig's rest angles: M^-1 = C T^T
  const Eigen::Vector3d hinge[2] = {cs.scenario.model.box.hinge_axis(1), cs.scenario.model.box.hinge_axis(2)};
  for (int i = 0; i < 2; ++i) {
    const Eigen::Matrix3d C_sim = unit_calibration(sim.sensor(i + 1).instance());
    // a unit with spread is not the nominal one (else the test would prove nothing)
    EXPECT_GT((C_sim - Eigen::Matrix3d::Identity()).norm(), 1e-3) << "sensor " << i + 1;
    for (int pos = 0; pos < 2; ++pos) {
      const Eigen::Matrix3d T = geo::rot_about_axis_deg(hinge[i], run.rest_angle_deg[i][pos]);
      const Eigen::Matrix3d C_rig = run.true_M.M(i, pos).inverse() * T;
      EXPECT_LE((C_rig - C_sim).norm(), 1e-12) << "sensor " << i + 1 << " position " << pos;
    }
  }
}

}  // namespace
}  // namespace driftless::calib
