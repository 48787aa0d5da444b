// Platform positions from the gyros alone (estimator/standstill_gyro.hpp), on readings made here
// from the sensor equation y_i = Rot(a_i, theta_i)^T w + theta_i' a_i + b_i: a turning box whose
// platforms flip one at a time and then both at once. The box rate made from the resting sensors
// is integrated and compared with the truth: the attitude the estimator makes in 'standstill: gyro'.
#include <array>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "estimator/geometry.hpp"
#include "estimator/standstill_gyro.hpp"

namespace driftless::est {
namespace {

constexpr double kRateHz = 100.0;
constexpr double kFlipS = 1.0;

// a raised-cosine flip from -amp.. to +amp (or back), like a motor with soft ends: angle, rate
struct Platform {
  std::vector<double> starts_s;
  double amp_deg = 90.0;
  void at(double t, double& angle_deg, double& rate_dps) const {
    double side = 1.0;
    angle_deg = amp_deg;
    rate_dps = 0.0;
    for (double t0 : starts_s) {
      if (t < t0) break;
      const double u = std::min(1.0, (t - t0) / kFlipS);
      const double s = u - std::sin(2.0 * M_PI * u) / (2.0 * M_PI);
      angle_deg = side * amp_deg * (1.0 - 2.0 * s);
      rate_dps = u < 1.0 ? -2.0 * side * amp_deg * (1.0 - std::cos(2.0 * M_PI * u)) / kFlipS : 0.0;
      if (u >= 1.0) side = -side;
    }
  }
};

Eigen::Vector3d box_rate_dps(double t) {
  return Eigen::Vector3d(20.0 * std::sin(0.5 * t), 10.0 * std::cos(0.3 * t), 30.0 * std::sin(0.2 * t));
}

struct TrackRun {
  double max_attitude_error_deg = 0.0;  // fused-rate attitude against the true one, largest
  int samples_both = 0;
  std::uint64_t simultaneous = 0;
  double p1_end = 0.0, p2_end = 0.0;
  bool rest_while_moving_wrongly = false;  // a platform said to rest with its hinge rate > 10 deg/s
};

TrackRun run(const Platform& pl1, const Platform& pl2, double duration_s) {
  BoxGeometry box;
  box.sample_rate_hz = kRateHz;
  box.validate();
  const Eigen::Vector3d b1(1.5, -0.7, 0.4), b2(-2.0, 0.3, 1.1);
  GyroFlipTracker tr(box, 5.0, 90.0, 90.0);
  Eigen::Quaterniond q_true = Eigen::Quaterniond::Identity(), q_est = q_true;
  TrackRun r;
  const double dt = 1.0 / kRateHz;
  for (int k = 0; k * dt <= duration_s; ++k) {
    const double t = k * dt;
    double th1, th1d, th2, th2d;
    pl1.at(t, th1, th1d);
    pl2.at(t, th2, th2d);
    const Eigen::Vector3d w = box_rate_dps(t);
    const Eigen::Vector3d y1 = geo::rot_about_axis_deg(box.hinge1_axis, th1).transpose() * w + th1d * box.hinge1_axis + b1;
    const Eigen::Vector3d y2 = geo::rot_about_axis_deg(box.hinge2_axis, th2).transpose() * w + th2d * box.hinge2_axis + b2;
    tr.push(y1, y2, b1, b2, k == 0 ? std::nan("") : dt);
    if (tr.motion() == GyroFlipTracker::Motion::kBoth) ++r.samples_both;
    r.rest_while_moving_wrongly |= (tr.rest(1) && std::fabs(th1d) > 10.0) || (tr.rest(2) && std::fabs(th2d) > 10.0);
    // the box rate as the estimator fuses it: the mean of the resting sensors turned into box axes
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int n = 0;
    if (tr.rest(1) && !tr.starting(1)) sum += geo::rot_about_axis_deg(box.hinge1_axis, tr.position_deg(1)) * (y1 - b1), ++n;
    if (tr.rest(2) && !tr.starting(2)) sum += geo::rot_about_axis_deg(box.hinge2_axis, tr.position_deg(2)) * (y2 - b2), ++n;
    EXPECT_GT(n, 0) << "no sensor at rest at t = " << t;
    if (n == 0) break;
    q_est = (q_est * geo::quat_from_rotvec(sum / n * kRadPerDeg * dt)).normalized();
    q_true = (q_true * geo::quat_from_rotvec(w * kRadPerDeg * dt)).normalized();
    const double err = geo::rotvec_rad(q_est * q_true.conjugate()).norm() * kDegPerRad;
    r.max_attitude_error_deg = std::max(r.max_attitude_error_deg, err);
  }
  r.simultaneous = tr.simultaneous_flips();
  r.p1_end = tr.position_deg(1);
  r.p2_end = tr.position_deg(2);
  return r;
}

TEST(GyroFlipTracker, OneFlipAtATimeOnATurningBoxKeepsTheAttitude) {
  // GIVEN a box turning at up to 30 deg/s, platforms flipping +-90 in turn (eq. (5)), 1 s each
  Platform p1{{12.0, 32.0, 52.0}}, p2{{2.0, 22.0, 42.0, 62.0}};
  // WHEN its rate is fused from the sensors the tracker says rest, at the positions it tracks
  const TrackRun r = run(p1, p2, 70.0);
  // THEN no flip was taken for a simultaneous one, the end positions are right (3 and 4 flips),
  EXPECT_EQ(r.simultaneous, 0u);
  EXPECT_EQ(r.samples_both, 0);
  EXPECT_EQ(r.p1_end, -90.0);
  EXPECT_EQ(r.p2_end, 90.0);
  EXPECT_FALSE(r.rest_while_moving_wrongly);
  // AND the attitude is within 0.01 deg of the truth after 7 flips: only the start of each flip,
  // below a fifth of the 5 deg/s threshold, enters at half weight (a raised-cosine flip of 180 deg
  // in 1 s reaches 1 deg/s after 17 ms, having turned 0.0054 deg: 0.0027 deg per flip)
  EXPECT_LT(r.max_attitude_error_deg, 7 * 0.0027);
}

TEST(GyroFlipTracker, BothPlatformsAtOnceAreSaidAndTrackedToTheirNewPositions) {
  // GIVEN one flip of platform 2, then both platforms flipping together at t = 12 s
  Platform p1{{12.0}}, p2{{2.0, 12.0}};
  // WHEN tracked to the end
  BoxGeometry box;
  box.sample_rate_hz = kRateHz;
  box.validate();
  const TrackRun whole = [&] {
    // no sensor reads the box rate while both move: look at the tracker alone
    TrackRun r;
    GyroFlipTracker tr(box, 5.0, 90.0, 90.0);
    const Eigen::Vector3d b1(1.5, -0.7, 0.4), b2(-2.0, 0.3, 1.1);
    for (int k = 0; k <= 2000; ++k) {
      const double t = k / kRateHz;
      double th1, th1d, th2, th2d;
      p1.at(t, th1, th1d);
      p2.at(t, th2, th2d);
      const Eigen::Vector3d w = box_rate_dps(t);
      tr.push(geo::rot_about_axis_deg(box.hinge1_axis, th1).transpose() * w + th1d * box.hinge1_axis + b1,
              geo::rot_about_axis_deg(box.hinge2_axis, th2).transpose() * w + th2d * box.hinge2_axis + b2, b1, b2,
              k == 0 ? std::nan("") : 1.0 / kRateHz);
      if (tr.motion() == GyroFlipTracker::Motion::kBoth) {
        ++r.samples_both;
        EXPECT_FALSE(tr.rest(1) || tr.rest(2));
        EXPECT_GT(t, 12.0);
        EXPECT_LT(t, 12.0 + kFlipS + 0.5);
      }
    }
    r.simultaneous = tr.simultaneous_flips();
    r.p1_end = tr.position_deg(1);
    r.p2_end = tr.position_deg(2);
    return r;
  }();
  // THEN that flip is counted as simultaneous, the span of both moving is said, and each
  // platform ends at its new stop (p1: +90 -> -90; p2: +90 -> -90 -> +90)
  EXPECT_EQ(whole.simultaneous, 1u);
  EXPECT_GT(whole.samples_both, int(0.5 * kRateHz));
  EXPECT_EQ(whole.p1_end, -90.0);
  EXPECT_EQ(whole.p2_end, 90.0);
  // AND up to the simultaneous flip the fused attitude was right
  const TrackRun before = run(p1, p2, 12.0);
  EXPECT_LT(before.max_attitude_error_deg, 2 * 0.0027);
  EXPECT_EQ(before.simultaneous, 0u);
}

}  // namespace
// GIVEN a log that starts half-way through platform 2's flip (+90 -> -90, -360 deg/s at t = 0) on
// a box turning at up to 30 deg/s, then a flip of platform 1 at 10 s and of platform 2 at 20 s,
// the bias estimate 0 (the filter's before any update)
// WHEN tracked from the first sample, the configuration's start positions (90, 90)
// THEN no platform is said to rest while it turns faster than 10 deg/s, the start is recorded
// (platform 2, its hinge rate at t = 0 within the box rate's 20 deg/s and the bias of -360, known
// 0.25 s after the flip's end at 0.5 s, within 0.1 s, at -90), and the positions
// follow the later flips: (-90, -90) at 15 s, (-90, +90) at the end. The same log starting at rest
// records no such start.
TEST(GyroFlipTracker, ALogStartingMidFlipWaitsForTheFlipToEndAndTakesItsStop) {
  BoxGeometry box;
  box.sample_rate_hz = kRateHz;
  box.validate();
  const Eigen::Vector3d b1(1.5, -0.7, 0.4), b2(-2.0, 0.3, 1.1), zero = Eigen::Vector3d::Zero();
  const auto track = [&](const Platform& pl1, const Platform& pl2, std::array<double, 2>& at_15, bool& wrong_rest) {
    GyroFlipTracker tr(box, 5.0, 90.0, 90.0);
    wrong_rest = false;
    for (int k = 0; k <= 3000; ++k) {
      const double t = k / kRateHz;
      double th1, th1d, th2, th2d;
      pl1.at(t, th1, th1d);
      pl2.at(t, th2, th2d);
      const Eigen::Vector3d w = box_rate_dps(t);
      tr.push(geo::rot_about_axis_deg(box.hinge1_axis, th1).transpose() * w + th1d * box.hinge1_axis + b1,
              geo::rot_about_axis_deg(box.hinge2_axis, th2).transpose() * w + th2d * box.hinge2_axis + b2, zero, zero,
              k == 0 ? std::nan("") : 1.0 / kRateHz, t);
      wrong_rest |= (tr.rest(1) && std::fabs(th1d) > 10.0) || (tr.rest(2) && std::fabs(th2d) > 10.0);
      if (k == 1500) at_15 = {tr.position_deg(1), tr.position_deg(2)};
    }
    return tr;
  };
  std::array<double, 2> at_15{};
  bool wrong_rest = true;
  const GyroFlipTracker tr = track(Platform{{10.0}}, Platform{{-0.5, 20.0}}, at_15, wrong_rest);
  EXPECT_FALSE(wrong_rest);
  const GyroFlipTracker::StartRecord& s = tr.start();
  EXPECT_TRUE(s.mid_flip);
  EXPECT_EQ(s.platform, 2);
  EXPECT_NEAR(s.rate_dps, -360.0, 20.0 + 2.0);
  EXPECT_EQ(s.t_first_s, 0.0);
  // the raised cosine's rate falls under the 5 deg/s threshold 0.0375 s before the flip's end
  // (1 - cos(2 pi u) = 5 / 180); the norms then agree within it, give or take the biases' part
  EXPECT_GE(s.t_known_s, 0.5 - 0.1 + 0.25);
  EXPECT_LE(s.t_known_s, 0.5 + 0.25 + 0.1);
  EXPECT_EQ(s.position_deg, -90.0);
  EXPECT_EQ(at_15[0], -90.0);
  EXPECT_EQ(at_15[1], -90.0);
  EXPECT_EQ(tr.position_deg(1), -90.0);
  EXPECT_EQ(tr.position_deg(2), 90.0);
  const GyroFlipTracker at_rest = track(Platform{{10.0}}, Platform{{20.0}}, at_15, wrong_rest);
  EXPECT_FALSE(at_rest.start().mid_flip);
  EXPECT_FALSE(wrong_rest);
  EXPECT_EQ(at_15[0], -90.0);
  EXPECT_EQ(at_15[1], 90.0);
}

}  // namespace driftless::est
