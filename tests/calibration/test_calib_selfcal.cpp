// calib.yaml from a self-calibration (docs/calibration.md): written, read back to the last bit,
// turned into the filter's calibration (G subtracted, temperature states starting at k with its
// sigma) and into a twin prior that plants G and k and nothing M would say.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "calibration/calib_file.hpp"
#include "calibration/prior.hpp"
#include "estimator/filter.hpp"
#include "estimator/geometry.hpp"
#include "tests/temp_path.hpp"

namespace driftless::calib {
namespace {

SelfCalibration planted() {
  SelfCalibration sc;
  sc.source = "test";
  sc.latitude_deg = 52.0;
  sc.sample_rate_hz = 100.0;
  sc.G_dps_per_g[1] << 0.0, 0.0304, 0.0, 0.0, -0.029, 0.0, 0.0, -0.0581, 0.0;
  sc.G_sigma[0].setConstant(0.0577);
  sc.G_sigma[1].setConstant(0.0577);
  sc.G_sigma[1].col(1) << 0.0015, 0.0012, 0.0017;
  sc.temp_states = true;
  sc.temp_coef_dps_per_degc = {Eigen::Vector3d(0.031, -0.049, 1.0 / 3.0), Eigen::Vector3d(-0.018, 0.072, -0.062)};
  sc.temp_coef_sigma_dps_per_degc = {Eigen::Vector3d::Constant(0.02), Eigen::Vector3d(0.022, 0.021, 0.021)};
  sc.temp_ref_c = {26.2, 26.3};
  return sc;
}

TEST(CalibSelfcal, TheFileReadsBackExactlyWithNominalMatrices) {
  // GIVEN a self-calibration written as calib.yaml
  const SelfCalibration sc = planted();
  const auto path = test::temp_path("selfcal_calib.yaml");
  save_selfcal_calib(path, sc);
  // WHEN it is read back
  const CalibFile c = load_calib(path);
  // THEN G and k and their sigma are the written doubles, M the nominal rotations
  EXPECT_EQ(c.method, "selfcal");
  EXPECT_TRUE(c.matrices_nominal);
  ASSERT_TRUE(c.has_g_sensitivity);
  ASSERT_TRUE(c.has_temp_coef);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(c.G_dps_per_g[i], sc.G_dps_per_g[i]);
    EXPECT_EQ(c.temp_coef_dps_per_degc[i], sc.temp_coef_dps_per_degc[i]);
    EXPECT_EQ(c.temp_coef_sigma_dps_per_degc[i], sc.temp_coef_sigma_dps_per_degc[i]);
    const Eigen::Vector3d a = i == 0 ? sc.hinge1_axis : sc.hinge2_axis;
    EXPECT_LT((c.M.M(static_cast<int>(i), 1) - geo::rot_about_axis_deg(a, 90.0)).norm(), 1e-15);
  }
}

TEST(CalibSelfcal, TheFilterStartsItsTemperatureStatesAtTheFile) {
  // GIVEN the file as the filter's calibration
  const auto path = test::temp_path("selfcal_calib_filter.yaml");
  save_selfcal_calib(path, planted());
  const est::Calibration cal = load_calib(path).to_filter_calibration();
  est::EstimatorConfig cfg;
  cfg.calibration = cal;
  // WHEN a filter is built with it
  const est::DriftlessFilter f(cfg, est::BoxGeometry{});
  // THEN the k states hold the file's values and sigma, M is left nominal (no matrices), G is set
  EXPECT_TRUE(cal.empty());
  EXPECT_EQ(cal.G_dps_per_g[1], planted().G_dps_per_g[1]);
  const est::Vector6d k = f.temp_coef_dps_per_degc(), ks = f.temp_coef_sigma_dps_per_degc();
  EXPECT_EQ(k.head<3>(), planted().temp_coef_dps_per_degc[0]);
  EXPECT_EQ(k.tail<3>(), planted().temp_coef_dps_per_degc[1]);
  EXPECT_NEAR(ks[3], 0.022, 1e-15);
  // and with the temperature states off the file's k are not used
  cfg.temp_coef_sigma_dps_per_degc = 0.0;
  const est::DriftlessFilter off(cfg, est::BoxGeometry{});
  EXPECT_EQ(off.temp_coef_dps_per_degc(), est::Vector6d::Zero());
}

TEST(CalibSelfcal, ThePriorPlantsGAndKOnly) {
  // GIVEN the file read back
  const auto path = test::temp_path("selfcal_calib_prior.yaml");
  save_selfcal_calib(path, planted());
  // WHEN it becomes a twin prior
  const YAML::Node m = YAML::Load(model_prior_yaml(load_calib(path)))["model"];
  // THEN each sensor gets G and the tempco (sigma 0: one sensor, not a population); no scale,
  // misalignment, mounting or stop errors (nominal M says nothing about them)
  EXPECT_FALSE(m["box"]["stop1_error_deg"]);
  const YAML::Node e = m["sensor2"]["effects"];
  EXPECT_FALSE(e["scale_factor"]);
  EXPECT_FALSE(e["mounting_misalignment"]);
  EXPECT_DOUBLE_EQ(e["g_sensitivity"]["matrix_dps_per_g"][2][1].as<double>(), -0.0581);
  EXPECT_DOUBLE_EQ(e["temperature"]["bias_tc_dps_per_degc"][1].as<double>(), 0.072);
  EXPECT_DOUBLE_EQ(e["temperature"]["bias_tc_sigma_dps_per_degc"][0].as<double>(), 0.0);
}

TEST(CalibSelfcal, ANegativeSigmaIsRefusedWithItsKey) {
  // GIVEN a file whose temperature sigma is negative
  const auto path = test::temp_path("selfcal_calib_bad.yaml");
  SelfCalibration sc = planted();
  sc.temp_coef_sigma_dps_per_degc[1].x() = -0.01;
  save_selfcal_calib(path, sc);
  // THEN reading it fails naming the key
  try {
    load_calib(path);
    FAIL() << "accepted";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("sensor2.temperature.bias_tc_sigma_dps_per_degc"), std::string::npos) << e.what();
  }
  // AND written in deg/h per degC (another unit of the same quantity) it is converted and refused alike
  std::string text;
  {
    std::ifstream in(path);
    text.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  for (std::size_t at; (at = text.find("bias_tc_sigma_dps_per_degc")) != std::string::npos;)
    text.replace(at, 26, "bias_tc_sigma_dph_per_degc");
  std::ofstream(path) << text;
  try {
    load_calib(path);
    FAIL() << "accepted in deg/h per degC";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("a sigma must be >= 0"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace driftless::calib
