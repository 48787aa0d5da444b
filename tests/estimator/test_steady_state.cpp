// The closed-form steady state of the bias filter (estimator/steady_state.hpp, docs/estimator.md
// section 6.5) against the textbook scalar Riccati fixed point and against iterating the six-state
// covariance recursion of the filter's windowed update (section 1h) over eq. (5)'s cycle.
#include <cmath>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "estimator/steady_state.hpp"

namespace driftless::est {
namespace {

// q (deg/s)^2/s, T s, window s, R (deg/s)^2: F27's noisy sensor (0.05 deg/s/rtHz, q 3e-5, 21 s
// between updates, 19.5 s windows), the MPU6050 defaults, a fast flipper and a slow one
const std::vector<UpdateSchedule> kSteadyStateSchedules = {
    {3.0e-5, 21.0, 19.5, 0.05 * 0.05 / 19.5},
    {1.85e-6, 21.0, 19.5, 0.005 * 0.005 / 19.5},
    {1.0e-4, 5.0, 3.0, 0.01 * 0.01 / 3.0},
    {1.0e-6, 120.0, 100.0, 0.02 * 0.02 / 100.0},
};

// the filter's recursion on [b1; b2] as filter.cpp runs it (predict q T, then the windowed
// update of section 1h in its Joseph form multiplied out), hinges z and x, rests cycling
// (+,+) -> (+,-) -> (-,-) -> (-,+); returns the largest and smallest sigma over the six
// components after each update of the last cycle, the largest first
std::pair<double, double> steady_state_by_iteration(const UpdateSchedule& s) {
  using M6 = Eigen::Matrix<double, 6, 6>;
  using H36 = Eigen::Matrix<double, 3, 6>;
  const double signs[4][2] = {{1, 1}, {1, -1}, {-1, -1}, {-1, 1}};
  M6 P = M6::Identity();
  const double c = 0.5 * s.window_s, v = s.window_s / 3.0;
  double hi = 0.0, lo = 1e300;
  for (int k = 0; k < 4000; ++k) {
    const double* sg = signs[k % 4];
    const Eigen::Matrix3d M1 = Eigen::AngleAxisd(sg[0] * M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const Eigen::Matrix3d M2 = Eigen::AngleAxisd(sg[1] * M_PI / 2, Eigen::Vector3d::UnitX()).toRotationMatrix();
    H36 H;
    H << M1, -M2;
    const Eigen::Matrix3d R = s.meas_var_dps2 * (M1 * M1.transpose() + M2 * M2.transpose());
    P.diagonal().array() += s.q_dps2_per_s * s.interval_s;
    const Eigen::Matrix<double, 6, 3> PHt = P * H.transpose() - s.q_dps2_per_s * c * H.transpose();
    const Eigen::Matrix3d S = H * PHt + R + s.q_dps2_per_s * (v - c) * H * H.transpose();
    const Eigen::Matrix<double, 6, 3> W = S.llt().solve(PHt.transpose()).transpose();
    const M6 WHP = W * PHt.transpose();
    P += W * S * W.transpose() - WHP - WHP.transpose();
    P = (0.5 * (P + P.transpose())).eval();
    if (k >= 3996) {
      const Eigen::Matrix<double, 6, 1> sigma = P.diagonal().cwiseSqrt();
      hi = std::max(hi, sigma.maxCoeff());
      lo = std::min(lo, sigma.minCoeff());
    }
  }
  return {hi, lo};
}

TEST(SteadyState, APointUpdateGivesTheTextbookScalarFixedPoint) {
  // GIVEN a scalar walk q updated every T by a measurement of variance R (no window)
  for (const UpdateSchedule& s : kSteadyStateSchedules) {
    const double qT = s.q_dps2_per_s * s.interval_s, R = s.meas_var_dps2;
    // WHEN the predict-then-update map's fixed point is taken
    const double p = attracting_fixed_point(predict_map(s.q_dps2_per_s, s.interval_s)
                                                .then(window_update_map(s.q_dps2_per_s, R, 0.0)));
    // THEN it is the posterior root of p^2 + qT p - qT R = 0, and a fixed point of the recursion
    const double closed = 0.5 * (-qT + std::sqrt(qT * qT + 4.0 * qT * R));
    EXPECT_NEAR(p, closed, 1e-12 * closed);
    EXPECT_NEAR((p + qT) * R / (p + qT + R), p, 1e-12 * p);
  }
}

TEST(SteadyState, MatchesIteratingTheSixStateRecursionOverTheCycle) {
  for (const UpdateSchedule& s : kSteadyStateSchedules) {
    // GIVEN the filter's own recursion run to its periodic steady state
    const auto [hi, lo] = steady_state_by_iteration(s);
    // WHEN the closed form is evaluated
    const SteadyState ss = bias_steady_state(s);
    // THEN the largest and smallest bias sigma of the cycle agree to rounding
    EXPECT_NEAR(ss.sigma_dps, hi, 1e-9 * hi) << "q " << s.q_dps2_per_s << " T " << s.interval_s;
    EXPECT_NEAR(ss.sigma_low_dps, lo, 1e-9 * lo) << "q " << s.q_dps2_per_s << " T " << s.interval_s;
    EXPECT_NEAR(ss.walk_per_update_dps, std::sqrt(s.q_dps2_per_s * s.interval_s), 1e-15);
  }
}

TEST(SteadyState, TheIntervalForATargetSigmaReachesIt) {
  // GIVEN F27's schedule, whose steady state (0.031 deg/s) a lock level of 0.025 cannot reach
  const UpdateSchedule s = kSteadyStateSchedules[0];
  const double now = bias_steady_state(s).sigma_dps;
  ASSERT_GT(now, 0.025);
  // WHEN the interval for 0.025 deg/s is solved for
  const double T = interval_for_sigma_s(s, 0.025);
  // THEN it is shorter, keeps the 1.5 s flip, and gives 0.025 deg/s
  ASSERT_TRUE(std::isfinite(T));
  EXPECT_LT(T, s.interval_s);
  UpdateSchedule t = s;
  t.interval_s = T;
  t.window_s = T - 1.5;
  t.meas_var_dps2 = s.meas_var_dps2 * s.window_s / t.window_s;
  EXPECT_NEAR(bias_steady_state(t).sigma_dps, 0.025, 1e-6);
  // a target already met keeps the interval; one below every schedule's sigma has no interval
  EXPECT_EQ(interval_for_sigma_s(s, 2.0 * now), s.interval_s);
  EXPECT_TRUE(std::isnan(interval_for_sigma_s(s, 0.001)));
}

TEST(SteadyState, NoScheduleNoSteadyState) {
  UpdateSchedule s = kSteadyStateSchedules[0];
  s.q_dps2_per_s = 0.0;  // no walk: the sigma shrinks for ever
  EXPECT_TRUE(std::isnan(bias_steady_state(s).sigma_dps));
  s = kSteadyStateSchedules[0];
  s.window_s = s.interval_s + 1.0;
  EXPECT_TRUE(std::isnan(bias_steady_state(s).sigma_dps));
  s = kSteadyStateSchedules[0];
  s.meas_var_dps2 = std::nan("");
  EXPECT_TRUE(std::isnan(bias_steady_state(s).sigma_dps));
}

}  // namespace
}  // namespace driftless::est
