// calib.yaml as a twin model prior: the emitted sensor effects and stop errors reproduce M.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "tests/calibration/calib_closed_form_rig.hpp"
#include "calibration/prior.hpp"
#include "estimator/geometry.hpp"
#include "twin/sensor/sensor_model.hpp"
#include "twin/yaml_doc.hpp"

namespace driftless::calib {

using twin::SensorParams;
using twin::SensorInstance;
using twin::ideal_sensor;
using twin::parse_yaml;
using twin::read_sensor_params;
namespace {

TEST(CalibPrior, SensorModelBuiltFromThePriorReproducesM) {
  // GIVEN the planted matrices as a calibration file
  CalibFile c;
  c.M = testing::planted_matrices();
  c.source = "test";
  const YAML::Node root = YAML::Load(model_prior_yaml(c));
  const Eigen::Vector3d hinge[2] = {c.hinge1_axis, c.hinge2_axis};
  for (int i = 0; i < 2; ++i) {
    // WHEN the twin's sensor model reads the prior (over a sensor with every effect off)
    const SensorParams p = read_sensor_params(*parse_yaml(model_prior_yaml(c), "prior.yaml")
                                                   .find("model")
                                                   ->find(i == 0 ? "sensor1" : "sensor2"),
                                               ideal_sensor(), fields::Context{"prior.yaml", ""});
    const SensorInstance inst = draw_sensor_instance(p, 1234);
    const Eigen::Matrix3d C = inst.misalignment * inst.scale.asDiagonal() * inst.R_sensor_from_nominal;
    const auto stops = root["model"]["box"][i == 0 ? "stop1_error_deg" : "stop2_error_deg"];
    // THEN C and the stops give back M at both end stops
    for (int pos = 0; pos < 2; ++pos) {
      const double angle = est::position_deg(pos) + stops[pos].as<double>();
      const Eigen::Matrix3d M = (C * geo::rot_about_axis_deg(hinge[i], angle).transpose()).inverse();
      EXPECT_LT((M - c.M.M(i, pos)).cwiseAbs().maxCoeff(), 1e-9) << "sensor " << i + 1 << " pos " << pos;
    }
    // and the planted magnitudes are visible: 2 % scale, 2 deg stop travel
    EXPECT_NEAR(std::abs(stops[1].as<double>()), 2.0, 1e-9);
    EXPECT_NEAR(p.scale_factor.value_pct.cwiseAbs().maxCoeff(), 2.0, 0.1);
  }
}

}  // namespace
}  // namespace driftless::calib
