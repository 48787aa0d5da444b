// calib.yaml from a self-calibration (docs/calibration.md): written, read back to the last bit,
// turned into the filter's calibration (G subtracted, temperature states starting at k with its
// sigma) and into a twin prior that plants G and k and nothing M would say.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include "calibration/calib_file.hpp"
#include "calibration/prior.hpp"
#include "estimator/filter.hpp"
#include "estimator/geometry.hpp"
#include "tests/estimator/synth.hpp"
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

// the planted self-calibration with a scale/misalignment E per sensor (fraction) and its sigma
SelfCalibration planted_with_e() {
  SelfCalibration sc = planted();
  sc.scale_states = true;
  sc.E_frac[0] << 0.012, 0.0, 0.0, 0.0, -0.009, 0.0, 0.0, 0.0, 0.010;  // diagonal: pure scale factors
  sc.E_frac[1] << -0.010, 0.006, 0.002, 0.003, 0.011, -0.007, -0.004, 0.005, -0.008;
  sc.E_sigma_frac[0].setConstant(0.0033);
  sc.E_sigma_frac[1].setConstant(0.0021);
  sc.E_sigma_frac[1](2, 0) = 0.0;  // exactly known: a frozen state
  return sc;
}

TEST(CalibSelfcal, ScaleMisalignmentReadsBackExactlyWithItsSigma) {
  // GIVEN a self-calibration with E written as calib.yaml
  const auto path = test::temp_path("selfcal_calib_e.yaml");
  const SelfCalibration sc = planted_with_e();
  save_selfcal_calib(path, sc);
  // WHEN it is read back and turned into the filter's calibration
  const CalibFile c = load_calib(path);
  const est::Calibration cal = c.to_filter_calibration();
  // THEN E, its sigma and G's sigma are the written doubles
  ASSERT_TRUE(c.has_scale_misalign);
  ASSERT_TRUE(cal.has_scale_misalign && cal.has_g_sigma);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(cal.E_frac[i], sc.E_frac[i]);
    EXPECT_EQ(cal.E_sigma_frac[i], sc.E_sigma_frac[i]);
    EXPECT_EQ(cal.G_sigma_dps_per_g[i], sc.G_sigma[i]);
  }
  // AND a file without E (a self-calibration with the scale states off) has none
  save_selfcal_calib(path, planted());
  EXPECT_FALSE(load_calib(path).has_scale_misalign);
}

TEST(CalibSelfcal, GAndEArePriorsWithSelfCalibrationAndFixedCorrectionsWithout) {
  const auto path = test::temp_path("selfcal_calib_e_filter.yaml");
  const SelfCalibration sc = planted_with_e();
  save_selfcal_calib(path, sc);
  est::EstimatorConfig cfg;
  cfg.calibration = load_calib(path).to_filter_calibration();
  // GIVEN the file WHEN the self-calibrating filter is built with it
  cfg.self_calibration = true;
  const est::DriftlessFilter on(cfg, est::BoxGeometry{});
  // THEN its G and E states start at the file's values with the file's sigma (a zero sigma: frozen)
  for (int i = 1; i <= 2; ++i) {
    const auto iu = static_cast<std::size_t>(i - 1);
    EXPECT_EQ(on.g_sensitivity_dps_per_g(i), sc.G_dps_per_g[iu]) << i;
    EXPECT_LT((on.g_sensitivity_sigma_dps_per_g(i) - sc.G_sigma[iu]).norm(), 1e-15) << i;
    EXPECT_EQ(on.scale_misalign(i), sc.E_frac[iu]) << i;
    EXPECT_LT((on.scale_misalign_sigma(i) - sc.E_sigma_frac[iu]).norm(), 1e-15) << i;
    // and M stays the rotation: E is in the state, not in M
    EXPECT_LT((on.body_from_sensor(i, 90.0) - geo::rot_about_axis_deg(i == 1 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitX(), 90.0)).norm(), 1e-15);
  }
  EXPECT_EQ(on.scale_misalign_sigma(2)(2, 0), 0.0);
  // WHEN the filter is built without self-calibration THEN no state holds them; E is folded into
  // M = R (I + E)^-1, so M^-1 = (I + E) R^T maps a box rate to what the sensor reads
  cfg.self_calibration = false;
  const est::DriftlessFilter off(cfg, est::BoxGeometry{});
  EXPECT_EQ(off.scale_misalign(2), Eigen::Matrix3d::Zero());
  EXPECT_EQ(off.g_sensitivity_dps_per_g(2), Eigen::Matrix3d::Zero());
  const Eigen::Vector3d w_box(10.0, -20.0, 30.0);
  const Eigen::Matrix3d R2 = geo::rot_about_axis_deg(Eigen::Vector3d::UnitX(), -90.0);
  const Eigen::Vector3d y2 = (Eigen::Matrix3d::Identity() + sc.E_frac[1]) * R2.transpose() * w_box;
  EXPECT_LT((off.body_from_sensor(2, -90.0) * y2 - w_box).norm(), 1e-12);
}

TEST(CalibSelfcal, ThePriorPlantsTheScaleFactorsOfE) {
  // GIVEN a file with E (sensor 1's diagonal: scale factors alone)
  const auto path = test::temp_path("selfcal_calib_e_prior.yaml");
  save_selfcal_calib(path, planted_with_e());
  // WHEN it becomes a twin prior
  const YAML::Node m = YAML::Load(model_prior_yaml(load_calib(path)))["model"];
  // THEN sensor 1's scale factors are E's diagonal in %, with no misalignment or mounting; the
  // stops stay unplanted (nominal M says nothing about them)
  EXPECT_FALSE(m["box"]["stop1_error_deg"]);
  const YAML::Node e = m["sensor1"]["effects"];
  ASSERT_TRUE(e["scale_factor"]) << YAML::Dump(m);
  const double want[3] = {1.2, -0.9, 1.0};
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(e["scale_factor"]["value_pct"][k].as<double>(), want[k], 1e-9) << k;
  EXPECT_NEAR(e["mounting_misalignment"]["angles_deg"][2].as<double>(), 0.0, 1e-9);
  EXPECT_NEAR(e["misalignment"]["matrix_pct"][0][1].as<double>(), 0.0, 1e-9);
}

TEST(CalibSelfcal, ANegativeOrLargeESigmaIsRefusedWithItsKey) {
  const auto path = test::temp_path("selfcal_calib_e_bad.yaml");
  for (const bool large : {false, true}) {
    // GIVEN a file with a negative sigma of E, or an E element of 60 %
    SelfCalibration sc = planted_with_e();
    if (large) sc.E_frac[1](0, 2) = 0.6;
    else sc.E_sigma_frac[1](1, 1) = -0.001;
    save_selfcal_calib(path, sc);
    // THEN reading it fails naming the key
    try {
      load_calib(path);
      FAIL() << "accepted";
    } catch (const InputError& e) {
      const std::string key = large ? "sensor2.scale_misalignment.E_frac" : "sensor2.scale_misalignment.E_sigma_frac";
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  }
}

// a box turning about every axis at about 30 deg/s with 20 s standstills: the flips and the turning
// observe most of E (docs/estimator.md section 1c); the same two sensors on two logs (other noise)
test::SynthParams turning_pair(std::uint64_t seed) {
  test::SynthParams p;
  p.duration_s = 1200.0;
  p.standstill_s = 20.0;
  p.noise_sigma_dps = 0.05;
  p.write_accel_temp = true;
  p.seed = seed;
  p.body_rate_dps = [](double t) {
    return Eigen::Vector3d(30.0 * std::sin(2.0 * kPi * t / 600.0), 30.0 * std::cos(2.0 * kPi * t / 780.0),
                           30.0 * std::sin(2.0 * kPi * t / 1020.0 + 1.0));
  };
  p.E_frac[0] << 0.012, 0.004, -0.006, -0.005, -0.009, 0.003, 0.007, -0.002, 0.010;
  p.E_frac[1] << -0.010, 0.006, 0.002, 0.003, 0.011, -0.007, -0.004, 0.005, -0.008;
  p.G_dps_per_g[1] << 0.0, 0.03, 0.0, 0.0, -0.03, 0.0, 0.0, -0.06, 0.0;
  return p;
}

est::DriftlessFilter selfcal_run(const test::SynthParams& p, const est::Calibration& cal) {
  est::EstimatorConfig cfg;
  cfg.self_calibration = true;
  cfg.q_override_dps2_per_s = 1e-12;  // constant biases
  cfg.calibration = cal;
  est::DriftlessFilter f(cfg, test::synth_geometry(p));
  test::synth_samples(p, [&](const Sample& s) { f.push(s); });
  f.finish();
  return f;
}

// the rms over the 18 E elements of (estimate - planted), fraction
double e_error_rms(const est::DriftlessFilter& f, const test::SynthParams& p) {
  double sum = 0.0;
  for (int i = 1; i <= 2; ++i) sum += (f.scale_misalign(i) - p.E_frac[static_cast<std::size_t>(i - 1)]).squaredNorm();
  return std::sqrt(sum / 18.0);
}

// GIVEN a turning box whose sensors have planted E and G
// WHEN the self-calibrating filter runs on a first log and its E and G (with sigma) are written as
// calib.yaml, read back and given to the self-calibrating filter on a second log of the same sensors
// THEN no sigma grew, the elements the first pass observed are known better after the second, the
// E error is smaller than after the first log or after the second log alone, nothing is rejected,
// and every element is within 5 sigma of the planted one. (5, not 3: on this motion one pass
// already puts the off-diagonal elements 1.7x too far for their sigma in variance, z up to 2.9,
// with or without G; two passes through the diagonal prior reach z = 4.3 on E2(0,1). Open, see
// docs/estimator.md section 1e.)
TEST(CalibSelfcal, ASelfCalibrationCarriedIntoTheNextLogRecoversEWithinSigma) {
  const test::SynthParams first = turning_pair(1), second = turning_pair(2);
  const est::DriftlessFilter a = selfcal_run(first, est::Calibration{});
  SelfCalibration sc;
  sc.scale_states = true;
  for (int i = 1; i <= 2; ++i) {
    const auto iu = static_cast<std::size_t>(i - 1);
    sc.G_dps_per_g[iu] = a.g_sensitivity_dps_per_g(i);
    sc.G_sigma[iu] = a.g_sensitivity_sigma_dps_per_g(i);
    sc.E_frac[iu] = a.scale_misalign(i);
    sc.E_sigma_frac[iu] = a.scale_misalign_sigma(i);
  }
  const auto path = test::temp_path("selfcal_calib_roundtrip.yaml");
  save_selfcal_calib(path, sc);
  const est::DriftlessFilter b = selfcal_run(second, load_calib(path).to_filter_calibration());
  const est::DriftlessFilter alone = selfcal_run(second, est::Calibration{});
  EXPECT_EQ(a.counters().rejected, 0u);
  EXPECT_EQ(b.counters().rejected, 0u);
  int better = 0;
  for (int i = 1; i <= 2; ++i) {
    const auto iu = static_cast<std::size_t>(i - 1);
    const Eigen::Matrix3d E = b.scale_misalign(i), S = b.scale_misalign_sigma(i);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(E(r, c), first.E_frac[iu](r, c), 5.0 * S(r, c)) << "E" << i << "(" << r << "," << c << ")";
        EXPECT_LE(S(r, c), sc.E_sigma_frac[iu](r, c) * (1.0 + 1e-9)) << "E" << i << "(" << r << "," << c << ")";
        if (S(r, c) < 0.8 * sc.E_sigma_frac[iu](r, c)) ++better;
      }
  }
  EXPECT_GE(better, 9);
  EXPECT_LT(e_error_rms(b, first), e_error_rms(a, first));
  EXPECT_LT(e_error_rms(b, first), e_error_rms(alone, first));
  // sensor 2's G column along gravity (its y) is carried too
  for (int r = 0; r < 3; ++r) {
    EXPECT_NEAR(b.g_sensitivity_dps_per_g(2)(r, 1), first.G_dps_per_g[1](r, 1), 3.0 * b.g_sensitivity_sigma_dps_per_g(2)(r, 1)) << r;
    EXPECT_LE(b.g_sensitivity_sigma_dps_per_g(2)(r, 1), sc.G_sigma[1](r, 1) * (1.0 + 1e-9)) << r;
  }
}

}  // namespace
}  // namespace driftless::calib
