// Flip updates (docs/estimator.md section 1f): the moving sensor's readings integrated over a
// flip measure its scale/misalignment along the hinge. Closed form on a noise-free flip of a
// turning box, then the filter on a noisy static box.
#include <cmath>

#include <gtest/gtest.h>

#include "estimator/filter.hpp"
#include "estimator/flip_update.hpp"
#include "estimator/geometry.hpp"
#include "tests/estimator/synth.hpp"

namespace driftless::est {
namespace {

// a box turning about every axis at up to 30 deg/s, both sensors with bias, g-sensitivity and
// 0.2-1.2 % scale/misalignment (the flips turned by (I + E) too)
test::SynthParams flipping_box(double minutes, double noise_dps) {
  test::SynthParams p;
  p.duration_s = 60.0 * minutes;
  p.standstill_s = 20.0;
  p.noise_sigma_dps = noise_dps;
  p.write_accel_temp = true;
  p.body_rate_dps = [](double t) {
    return Eigen::Vector3d(30.0 * std::sin(2.0 * kPi * t / 60.0), 30.0 * std::cos(2.0 * kPi * t / 78.0),
                           30.0 * std::sin(2.0 * kPi * t / 102.0 + 1.0));
  };
  p.E_frac[0] << 0.012, 0.004, -0.006, -0.005, -0.009, 0.003, 0.007, -0.002, 0.010;
  p.E_frac[1] << -0.010, 0.006, 0.002, 0.003, 0.011, -0.007, -0.004, 0.005, -0.008;
  p.G_dps_per_g[0] << 0.03, -0.02, 0.05, 0.01, 0.04, -0.03, 0.02, 0.06, -0.01;
  p.G_dps_per_g[1] << -0.04, 0.02, 0.01, 0.05, -0.03, 0.02, -0.01, 0.03, 0.04;
  return p;
}

SensorErrors truth(const test::SynthParams& p, int sensor) {
  SensorErrors e;
  e.b_dps = sensor == 1 ? p.b1_dps : p.b2_dps;
  e.G_dps_per_g = p.G_dps_per_g[static_cast<std::size_t>(sensor - 1)];
  e.E_frac = p.E_frac[static_cast<std::size_t>(sensor - 1)];
  return e;
}

// the state vector of the blocks flip_rows() fills, for sensor m moving and r resting
Eigen::Matrix<double, 42, 1> blocks(const SensorErrors& m, const SensorErrors& r) {
  using RowMajor3 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;
  Eigen::Matrix<double, 42, 1> x;
  const RowMajor3 Gm = m.G_dps_per_g, Gr = r.G_dps_per_g, Em = m.E_frac, Er = r.E_frac;
  x << m.b_dps, r.b_dps, Eigen::Map<const Eigen::Matrix<double, 9, 1>>(Gm.data()),
      Eigen::Map<const Eigen::Matrix<double, 9, 1>>(Gr.data()), Eigen::Map<const Eigen::Matrix<double, 9, 1>>(Em.data()),
      Eigen::Map<const Eigen::Matrix<double, 9, 1>>(Er.data());
  return x;
}

// GIVEN noise-free flips of a box turning at up to 30 deg/s, both sensors with planted b, G, E
// WHEN each flip's window is cut out and flip_rows() builds its measurement with the true errors
// THEN z = H x (to 2e-3 deg: second order in E and the profile, against a signal E a Δθ of about 2 deg and a
// noise sigma of 0.009 deg for the MPU6050), for both platforms and both directions
TEST(FlipUpdateTest, TheFlipMeasurementIsExactOnANoiseFreeFlip) {
  const test::SynthParams p = flipping_box(2.0, 0.0);
  const BoxGeometry box = test::synth_geometry(p);
  EstimatorConfig cfg;
  StandstillDetector detector(cfg, box);
  FlipWindow window(cfg.settle_s, cfg.flip_max_s, p.rate_hz);
  int closed[2] = {0, 0};
  double last_t = kNaN;
  test::synth_samples(p, [&](const Sample& s) {
    const double dt = std::isfinite(last_t) ? s.t_s - last_t : kNaN;
    last_t = s.t_s;
    const StandstillStep st = detector.push(s, dt, p.b1_dps, p.b2_dps);
    if (window.push(s, dt, st) != FlipWindow::Event::kClosed) return;
    const int m = window.moving(), r = 3 - m;
    FlipModel fm;
    fm.M_moving_start = geo::rot_about_axis_deg(m == 1 ? p.hinge1 : p.hinge2, window.start_deg());
    fm.M_rest = geo::rot_about_axis_deg(r == 1 ? p.hinge1 : p.hinge2, window.rest_deg());
    fm.hinge_box = m == 1 ? p.hinge1 : p.hinge2;
    fm.moving = truth(p, m);
    fm.rest = truth(p, r);
    fm.use_g = true;
    fm.sample_var_dps2 = 0.0025;
    fm.angle_sigma_deg = 0.05;
    const FlipRows fr = flip_rows(window, fm);
    ASSERT_TRUE(fr.valid) << "flip of platform " << m << " at t = " << s.t_s;
    Eigen::Matrix<double, 3, 42> H;
    H << fr.H_b_moving, fr.H_b_rest, fr.H_G_moving, fr.H_G_rest, fr.H_E_moving, fr.H_E_rest;
    // the generator samples the raised-cosine flip rate at instants: the rectangle rule over its
    // N = 100 samples turns by kappa = (pi / 2N) cot(pi / 2N) = 1 - 8.2e-5 of the angle
    const double h = kPi / (2.0 * p.flip_s * p.rate_hz), kappa = h / std::tan(h);
    const Eigen::Vector3d a = m == 1 ? p.hinge1 : p.hinge2;  // = its sensor-axes hinge at 0 / 90 deg
    const Eigen::Vector3d predicted = H * blocks(fm.moving, fm.rest) +
                                      (kappa - 1.0) * (window.end_deg() - window.start_deg()) * (a + fm.moving.E_frac * a);
    EXPECT_LT((fr.z_deg - predicted).cwiseAbs().maxCoeff(), 2e-3) << "platform " << m << " at t = " << s.t_s;
    const Eigen::Vector3d e_part = fr.H_E_moving * blocks(fm.moving, fm.rest).segment<9>(24);
    EXPECT_GT(e_part.norm(), 0.5) << "the flip's E signal, deg";
    // white noise of 1.0 s + 0.5 s settle of two sensors plus the two rest angles along the hinge,
    // and the rectangle rule's term: the largest change of the turn from one sample to the next,
    // here the raised cosine's Δθ (pi^2 / 2) dt^2 / flip_s^2 = 0.089 deg, squared over 12 (along
    // the hinge, and at most 30 deg/s x 1.5 s of box rate turned by it across)
    const double base = 3.0 * 2.0 * 0.0025 * fr.span_s * 0.01 + 2.0 * 0.05 * 0.05;
    const double jump_deg = 180.0 * kPi * kPi / 2.0 * 0.01 * 0.01, q = jump_deg * jump_deg / 12.0;
    EXPECT_GT(fr.R_deg2.trace(), base + 0.9 * q);
    EXPECT_LT(fr.R_deg2.trace(), base + 1.01 * q * (1.0 + 2.0 * std::pow(kRadPerDeg * 52.0 * 1.5, 2)));
    ++closed[m - 1];
  });
  EXPECT_GE(closed[0], 2);
  EXPECT_GE(closed[1], 2);
}

// GIVEN the angle columns' change and the gyros' turn over a flip WHEN Δθ is taken modulo 360
// THEN it is the representative nearest the turn: a one-way platform's +90 -> -90 (read -180)
// that turned +180 is +180; a back-and-forth flip keeps its reading; NaN stays NaN
TEST(FlipUpdateTest, TheAngleChangeIsTakenModulo360WithTheTurnTheGyrosSaw) {
  EXPECT_DOUBLE_EQ(nearest_turn_mod_360_deg(-180.0, 179.2), 180.0);
  EXPECT_DOUBLE_EQ(nearest_turn_mod_360_deg(180.0, -181.5), -180.0);
  EXPECT_DOUBLE_EQ(nearest_turn_mod_360_deg(-180.0, -178.0), -180.0);
  EXPECT_DOUBLE_EQ(nearest_turn_mod_360_deg(90.0, 91.0), 90.0);
  EXPECT_DOUBLE_EQ(nearest_turn_mod_360_deg(-270.0, 88.0), 90.0);   // 135 -> -135 read, +90 turned
  EXPECT_DOUBLE_EQ(nearest_turn_mod_360_deg(170.0, -540.0), -550.0);  // a whole turn and a half
  EXPECT_TRUE(std::isnan(nearest_turn_mod_360_deg(kNaN, 180.0)));
  EXPECT_DOUBLE_EQ(nearest_turn_mod_360_deg(-180.0, kNaN), -180.0);
}

EstimatorConfig selfcal(bool flips) {
  EstimatorConfig cfg;
  cfg.self_calibration = true;
  cfg.q_override_dps2_per_s = 1e-12;
  cfg.flip_updates = flips;
  return cfg;
}

// GIVEN a static box (the Earth rate only) whose sensors have 0.2-1.2 % scale/misalignment,
// 0.005 deg/s/rtHz noise, exact end stops
// WHEN the self-calibrating filter runs 10 minutes without flip updates THEN E keeps its prior;
// WHEN it runs with them THEN each sensor's E column along its hinge (E1 . z, E2 . x) is
// recovered within 3 sigma with sigma below 0.05 of the prior (one flip: sqrt(2) 0.05 deg of the
// rest angles over 180 deg, 4e-4), no flip update is rejected, and the other columns keep the prior
TEST(FlipUpdateTest, FlipsObserveTheScaleAndMisalignmentAlongTheHinge) {
  test::SynthParams p = flipping_box(10.0, 0.05);
  p.body_rate_dps = nullptr;
  const auto run = [&](const EstimatorConfig& cfg) {
    DriftlessFilter f(cfg, test::synth_geometry(p));
    test::synth_samples(p, [&](const Sample& s) { f.push(s); });
    f.finish();
    return f;
  };
  const DriftlessFilter without = run(selfcal(false));
  EXPECT_EQ(without.counters().flip_updates, 0u);
  EXPECT_GT(without.scale_misalign_sigma(1).minCoeff(), 0.9 * selfcal(true).scale_misalign_sigma_frac);
  const DriftlessFilter f = run(selfcal(true));
  EXPECT_GT(f.counters().flip_updates, 20u);
  EXPECT_EQ(f.counters().flip_rejected, 0u);
  EXPECT_EQ(f.counters().rejected, 0u);
  const double prior = selfcal(true).scale_misalign_sigma_frac;
  for (int i = 1; i <= 2; ++i) {
    const int hinge_col = i == 1 ? 2 : 0;  // hinge 1 = z, hinge 2 = x
    const Eigen::Matrix3d E = f.scale_misalign(i), S = f.scale_misalign_sigma(i);
    for (int r = 0; r < 3; ++r) {
      EXPECT_NEAR(E(r, hinge_col), p.E_frac[static_cast<std::size_t>(i - 1)](r, hinge_col), 3.0 * S(r, hinge_col))
          << "E" << i << "(" << r << "," << hinge_col << ")";
      EXPECT_LT(S(r, hinge_col), 0.05 * prior) << "E" << i << "(" << r << "," << hinge_col << ")";
      for (int c = 0; c < 3; ++c) {
        if (c == hinge_col) continue;
        EXPECT_GT(S(r, c), 0.9 * prior) << "E" << i << "(" << r << "," << c << ")";
      }
    }
  }
}

// GIVEN the same static box with g-sensitivity in its readings but no accel columns in the log
// (P13: the flips were dropped whole, 0 flip updates, no word)
// WHEN the self-calibrating filter runs THEN the flips are used without the G columns, G f's
// prior variance in R: the hinge columns of E are recovered within 3 sigma, sigma below a tenth of
// the prior, no flip rejected; and every G element keeps its prior sigma (nothing observes it)
TEST(FlipUpdateTest, FlipsWithoutAccelColumnsAreUsedWithoutTheGColumns) {
  test::SynthParams p = flipping_box(10.0, 0.05);
  p.body_rate_dps = nullptr;
  p.write_accel_temp = false;
  DriftlessFilter f(selfcal(true), test::synth_geometry(p));
  test::synth_samples(p, [&](const Sample& s) { f.push(s); });
  f.finish();
  EXPECT_GT(f.counters().flip_updates, 20u);
  EXPECT_EQ(f.counters().flip_rejected, 0u);
  const double prior = selfcal(true).scale_misalign_sigma_frac;
  const double g_prior = selfcal(true).gsens_sigma_dps_per_g;
  for (int i = 1; i <= 2; ++i) {
    const int hinge_col = i == 1 ? 2 : 0;
    const Eigen::Matrix3d E = f.scale_misalign(i), S = f.scale_misalign_sigma(i);
    for (int r = 0; r < 3; ++r) {
      EXPECT_NEAR(E(r, hinge_col), p.E_frac[static_cast<std::size_t>(i - 1)](r, hinge_col), 3.0 * S(r, hinge_col))
          << "E" << i << "(" << r << "," << hinge_col << ")";
      EXPECT_LT(S(r, hinge_col), 0.1 * prior) << "E" << i << "(" << r << "," << hinge_col << ")";
    }
    EXPECT_GT(f.g_sensitivity_sigma_dps_per_g(i).minCoeff(), 0.99 * g_prior) << "G" << i;
  }
}

// GIVEN the static box of the test above, flips of 180 deg in 1 s (a 283 deg/s peak), and sensor 1
// clipping at +-260 deg/s, so its integrated turn falls about 5 deg short in each of its flips
// WHEN the self-calibrating filter runs with flip updates, on the clipped log and on the same log
// unclipped
// THEN on the clipped log every flip of platform 1 is skipped (counted in flip_clipped), sensor 1's
// E column along its hinge keeps about its prior sigma and is not pulled by the short turns, while
// platform 2's flips, which no gyro clipped, still measure E2's; the unclipped log skips none
TEST(FlipUpdateTest, AFlipInWhichAGyroClippedIsSkipped) {
  test::SynthParams p = flipping_box(10.0, 0.05);
  p.body_rate_dps = nullptr;
  p.lsb_dps = 1.0 / 65.5;
  const auto run = [&](bool clip) {
    test::SynthParams q = p;
    if (clip) q.before_quantise = [](Sample& s) { s.gyro1_dps = s.gyro1_dps.cwiseMax(-260.0).cwiseMin(260.0); };
    DriftlessFilter f(selfcal(true), test::synth_geometry(q));
    test::synth_samples(q, [&](const Sample& s) { f.push(s); });
    f.finish();
    return f;
  };
  const DriftlessFilter clean = run(false), clipped = run(true);
  EXPECT_EQ(clean.counters().flip_clipped, 0u);
  EXPECT_GT(clean.counters().flip_updates, 20u);
  // platform 1 flips every other cycle of eq. (5): about half of the flips
  EXPECT_GE(clipped.counters().flip_clipped, 10u);
  EXPECT_EQ(clipped.counters().flip_clipped + clipped.counters().flip_updates, clean.counters().flip_updates);
  // (used, a short turn is 5 deg against a flip sigma of about 0.1 deg: the flip gate rejects it)
  EXPECT_EQ(clipped.counters().flip_rejected, 0u);
  const double prior = selfcal(true).scale_misalign_sigma_frac;
  const Eigen::Matrix3d E1 = clipped.scale_misalign(1), S1 = clipped.scale_misalign_sigma(1);
  const Eigen::Matrix3d S2 = clipped.scale_misalign_sigma(2);
  for (int r = 0; r < 3; ++r) {
    EXPECT_NEAR(E1(r, 2), p.E_frac[0](r, 2), 3.0 * S1(r, 2)) << "E1(" << r << ",z)";
    EXPECT_GT(S1(r, 2), 0.5 * prior) << "E1(" << r << ",z)";
    EXPECT_LT(S2(r, 0), 0.05 * prior) << "E2(" << r << ",x)";
  }
}

}  // namespace
}  // namespace driftless::est
