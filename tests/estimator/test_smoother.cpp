// The offline fixed-interval smoother (docs/estimator.md section 6.3): against the closed form of
// a scalar random walk seen at three updates (the joint Gaussian solved directly, and the Brownian
// bridge between the updates), then on the filter over a synthetic log: no steps between updates,
// sigma never above the filter's, errors smaller than the filter's and inside 3 sigma.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "estimator/smoother.hpp"
#include "tests/estimator/synth.hpp"

namespace driftless::est {
namespace {

// one scalar state (b1_x) as the whole active state: a random walk of rate q, measured directly
struct ScalarKf {
  double q, x, P, t;
  StateVector xv = StateVector::Zero(), xpv = StateVector::Zero();
  StateMatrix Pm = StateMatrix::Zero(), Ppm = StateMatrix::Zero();
  // predict to t_s, update with z of variance r; hands both to the smoother
  void update(double t_s, double z, double r, UpdateObserver& obs) {
    P += q * (t_s - t);
    t = t_s;
    xpv[0] = x;
    Ppm(0, 0) = P;
    const double k = P / (P + r);
    x += k * (z - x);
    P *= 1.0 - k;
    xv[0] = x;
    Pm(0, 0) = P;
    obs.on_accepted_update({t_s, {kNaN, kNaN}, &xpv, &Ppm, &xv, &Pm});
  }
};

// GIVEN a random walk (q = 0.01 per s) with prior 0 +- 2 at t = 0, measured at t = 0, 10, 30 s
// WHEN it is smoothed THEN at the updates the mean and variance are those of the joint Gaussian
// of (x0, x10, x30) solved in information form, and in between those of the Brownian bridge:
// mean (1 - s) m_a + s m_b, variance (1-s)^2 P_aa + s^2 P_bb + 2 s (1-s) P_ab + q tau (T - tau) / T
TEST(SmootherTest, ARandomWalkBetweenUpdatesIsTheBrownianBridgeOfTheBatchSolution) {
  const double q = 0.01, p0 = 4.0;
  const std::vector<double> ts{0.0, 10.0, 30.0}, zs{1.0, 1.4, 0.7}, rs{0.5, 0.2, 0.3};
  FixedIntervalSmoother sm(q);
  ScalarKf kf{q, 0.0, p0, 0.0};
  for (std::size_t k = 0; k < 3; ++k) kf.update(ts[k], zs[k], rs[k], sm);
  sm.smooth();
  // the batch solution: information matrix of (x0, x1, x2)
  Eigen::Matrix3d I = Eigen::Matrix3d::Zero();
  Eigen::Vector3d h = Eigen::Vector3d::Zero();
  I(0, 0) += 1.0 / p0;
  for (int k = 0; k < 3; ++k) {
    I(k, k) += 1.0 / rs[static_cast<std::size_t>(k)];
    h[k] += zs[static_cast<std::size_t>(k)] / rs[static_cast<std::size_t>(k)];
  }
  for (int k = 0; k < 2; ++k) {
    const double w = 1.0 / (q * (ts[static_cast<std::size_t>(k + 1)] - ts[static_cast<std::size_t>(k)]));
    I(k, k) += w;
    I(k + 1, k + 1) += w;
    I(k, k + 1) -= w;
    I(k + 1, k) -= w;
  }
  const Eigen::Matrix3d P = I.inverse();
  const Eigen::Vector3d m = P * h;
  for (int k = 0; k < 2; ++k) {
    const double ta = ts[static_cast<std::size_t>(k)], T = ts[static_cast<std::size_t>(k + 1)] - ta;
    for (const double s : {0.0, 0.25, 0.5, 0.9}) {
      const double tau = s * T;
      const SmoothedState& st = sm.at(ta + tau);
      const double mean = (1.0 - s) * m[k] + s * m[k + 1];
      const double var = (1 - s) * (1 - s) * P(k, k) + s * s * P(k + 1, k + 1) + 2 * s * (1 - s) * P(k, k + 1) +
                         q * tau * (T - tau) / T;
      EXPECT_NEAR(st.x[0], mean, 1e-12) << "t = " << ta + tau;
      EXPECT_NEAR(st.var[0], var, 1e-12) << "t = " << ta + tau;
    }
  }
  // AND after the last update: the filtered value, its variance growing by q per second
  const SmoothedState& end = sm.at(40.0);
  EXPECT_NEAR(end.x[0], m[2], 1e-12);
  EXPECT_NEAR(end.var[0], P(2, 2) + q * 10.0, 1e-12);
  EXPECT_EQ(sm.updates(), 3u);
}

// a box flipping every 10 s with random-walk biases (1e-3 deg/s per sample step: 0.0316 deg/s per
// sqrt(s), far above the default Q, so the filter is told: q_override) and MPU6050 noise
struct SmoothRun {
  std::vector<Eigen::Vector3d> filtered1, smoothed1;  // the correction y1 - y1c, deg/s
  std::vector<Vector6d> truth;
  std::vector<StateVector> smoothed_var;
  std::vector<Vector6d> filtered_var;  // P at the last update + q (t - t_update)
};

SmoothRun run_both(const test::SynthParams& p, const EstimatorConfig& cfg) {
  SmoothRun out;
  const BoxGeometry box = test::synth_geometry(p);
  FixedIntervalSmoother sm(cfg.q_dps2_per_s());
  DriftlessFilter first(cfg, box);
  first.set_update_observer(&sm);
  double t_upd = kNaN;
  Vector6d p_upd = Vector6d::Zero();
  test::synth_samples(p, [&](const Sample& s) {
    const PushStatus st = first.push(s);
    if (st == PushStatus::kUpdated) {
      t_upd = s.t_s;
      p_upd = first.covariance_dps2().diagonal();
    }
    out.filtered1.push_back(s.gyro1_dps - first.output().y1c_dps);
    Vector6d tr;
    tr << s.true_bias1_dps, s.true_bias2_dps;
    out.truth.push_back(tr);
    out.filtered_var.push_back(std::isfinite(t_upd) ? Vector6d(p_upd.array() + cfg.q_dps2_per_s() * (s.t_s - t_upd))
                                                    : Vector6d::Constant(kNaN));
  });
  first.finish();
  sm.smooth();
  DriftlessFilter second(cfg, box);
  test::synth_samples(p, [&](const Sample& s) {
    const SmoothedState& st = sm.at(s.t_s);
    second.set_output_state(&st.x, &st.temp_ref_c);
    second.push(s);
    out.smoothed1.push_back(s.gyro1_dps - second.output().y1c_dps);
    out.smoothed_var.push_back(st.var);
  });
  return out;
}

// GIVEN 10 minutes of that box WHEN the filter runs and is smoothed THEN the smoothed correction
// moves by less than 2e-4 deg/s from sample to sample (the filter's jumps by more than 20x that at
// updates), its variance is never above the filter's, its rms error is below the filter's, and
// 95 % of its errors lie within 3 sigma
TEST(SmootherTest, TheSmoothedCorrectionHasNoStepsAndIsBetterThanTheFilter) {
  test::SynthParams p;
  p.duration_s = 600.0;
  p.noise_sigma_dps = 0.05;
  p.bias_walk_dps = 1e-3;
  p.seed = 7;
  EstimatorConfig cfg;
  cfg.q_override_dps2_per_s = 1e-6 * p.rate_hz;  // (1e-3)^2 per sample
  cfg.temp_coef_sigma_dps_per_degc = 0.0;
  const SmoothRun r = run_both(p, cfg);
  ASSERT_EQ(r.filtered1.size(), r.smoothed1.size());
  double step_f = 0.0, step_s = 0.0, e2_f = 0.0, e2_s = 0.0;
  std::size_t in3 = 0, n = 0;
  const std::size_t start = 2000;  // after the first updates (20 s)
  for (std::size_t k = start; k < r.filtered1.size(); ++k) {
    step_f = std::max(step_f, (r.filtered1[k] - r.filtered1[k - 1]).cwiseAbs().maxCoeff());
    step_s = std::max(step_s, (r.smoothed1[k] - r.smoothed1[k - 1]).cwiseAbs().maxCoeff());
    const Eigen::Vector3d ef = r.filtered1[k] - r.truth[k].head<3>(), es = r.smoothed1[k] - r.truth[k].head<3>();
    e2_f += ef.squaredNorm();
    e2_s += es.squaredNorm();
    for (int i = 0; i < 3; ++i) {
      EXPECT_LE(r.smoothed_var[k][i], r.filtered_var[k][i] * (1.0 + 1e-9)) << "sample " << k << " axis " << i;
      in3 += std::fabs(es[i]) <= 3.0 * std::sqrt(r.smoothed_var[k][i]) ? 1 : 0;
      ++n;
    }
  }
  EXPECT_LT(step_s, 2e-4);
  EXPECT_GT(step_f, 20.0 * 2e-4);
  EXPECT_LT(e2_s, 0.8 * e2_f);
  EXPECT_GT(double(in3) / double(n), 0.95);
}

// the correction of sensor 1 that state `f` closes with applies to sample `s`, y1c = (I - E1) (y1 -
// b1 - G1 f1) (docs/estimator.md section 1c), and its 1-sigma per axis from the state's sigma
struct ClosedForm {
  Eigen::Vector3d y1c_dps, sigma_dps;
};
ClosedForm closed_form(const DriftlessFilter& f, const Sample& s) {
  const Eigen::Vector3d f1_g = s.accel1_mps2 / kStandardGravityMps2;
  const Eigen::Vector3d o = s.gyro1_dps - f.bias1_dps() - f.g_sensitivity_dps_per_g(1) * f1_g;
  ClosedForm c{o - f.scale_misalign(1) * o, Eigen::Vector3d::Zero()};
  const Eigen::Matrix3d sE = f.scale_misalign_sigma(1), sG = f.g_sensitivity_sigma_dps_per_g(1);
  for (int r = 0; r < 3; ++r) {
    double v = f.sigma_dps()[r] * f.sigma_dps()[r];
    for (int j = 0; j < 3; ++j) v += sE(r, j) * sE(r, j) * o[j] * o[j] + sG(r, j) * sG(r, j) * f1_g[j] * f1_g[j];
    c.sigma_dps[r] = std::sqrt(v);
  }
  return c;
}

// the largest |a - b| / sigma over the axes
double z_max(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& sigma) {
  return (a - b).cwiseAbs().cwiseQuotient(sigma).maxCoeff();
}

// GIVEN a box turning about every axis at up to 30 deg/s whose sensor 1 reads every axis 2 % large
// (a constant scale error E1 = 0.02 I), constant biases (the filter told so), self-calibrating
// WHEN the filter runs, is smoothed, and the second pass writes its rows
// THEN every smoothed row, from the first, is the closed form with the final estimate (b1, G1, E1)
// within its sigma, while the filter's rows are off by more than 5 sigma before it learnt E from the
// standstills and the flips and within 3 sigma only at the end; the E part (up to 0.6 deg/s) is
// well above that sigma, so a second pass that kept the filter's E would fail here
TEST(SmootherTest, SelfCalibratingRowsUseTheSmoothedScaleFactorFromTheStart) {
  test::SynthParams p;
  p.duration_s = 900.0;
  p.standstill_s = 20.0;
  p.noise_sigma_dps = 0.05;
  p.write_accel_temp = true;
  p.seed = 11;
  p.body_rate_dps = [](double t) {
    return Eigen::Vector3d(30.0 * std::sin(2.0 * kPi * t / 600.0), 30.0 * std::cos(2.0 * kPi * t / 780.0),
                           30.0 * std::sin(2.0 * kPi * t / 1020.0 + 1.0));
  };
  p.E_frac[0] = 0.02 * Eigen::Matrix3d::Identity();
  EstimatorConfig cfg;
  cfg.self_calibration = true;
  cfg.q_override_dps2_per_s = 1e-12;  // constant biases
  const BoxGeometry box = test::synth_geometry(p);
  std::vector<Sample> samples;
  test::synth_samples(p, [&](const Sample& s) { samples.push_back(s); });
  FixedIntervalSmoother sm(cfg.q_dps2_per_s());
  DriftlessFilter first(cfg, box);
  first.set_update_observer(&sm);
  std::vector<Eigen::Vector3d> filtered;
  for (const Sample& s : samples) {
    first.push(s);
    filtered.push_back(first.output().y1c_dps);
  }
  first.finish();
  ASSERT_TRUE(first.has_scale_states());
  ASSERT_EQ(first.counters().rejected, 0u);
  sm.smooth();
  std::size_t k = 0, early = 0, filtered_off_early = 0;
  double worst_smoothed = 0.0, largest_e_part = 0.0, worst_filtered_end = 0.0;
  smoothed_outputs(
      cfg, box, [&](Sample& s) { return k < samples.size() ? (s = samples[k], true) : false; }, sm,
      [&](const Sample& s, const SampleOutput& o) {
        const ClosedForm c = closed_form(first, s);
        worst_smoothed = std::max(worst_smoothed, z_max(o.y1c_dps, c.y1c_dps, c.sigma_dps));
        const Eigen::Vector3d e_part = first.scale_misalign(1) * (s.gyro1_dps - first.bias1_dps());
        largest_e_part = std::max(largest_e_part, z_max(e_part, Eigen::Vector3d::Zero(), c.sigma_dps));
        const double z_f = z_max(filtered[k], c.y1c_dps, c.sigma_dps);
        if (s.t_s < 60.0) {
          ++early;
          filtered_off_early += z_f > 5.0 ? 1 : 0;
        }
        if (s.t_s > p.duration_s - 100.0) worst_filtered_end = std::max(worst_filtered_end, z_f);
        ++k;
      });
  std::printf("[ info ] %zu rows: smoothed within %.3g sigma of the closed form; the E part up to %.3g sigma; "
              "filtered rows off by > 5 sigma: %zu of %zu in the first 60 s, within %.3g sigma in the last 100 s\n",
              k, worst_smoothed, largest_e_part, filtered_off_early, early, worst_filtered_end);
  ASSERT_EQ(k, samples.size());
  EXPECT_LE(worst_smoothed, 1.0);
  EXPECT_GT(largest_e_part, 20.0);
  EXPECT_GT(filtered_off_early, early / 2);
  EXPECT_LE(worst_filtered_end, 3.0);
}

}  // namespace
}  // namespace driftless::est
