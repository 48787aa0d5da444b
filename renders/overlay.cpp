#include "renders/overlay.hpp"

#include "estimator/geometry.hpp"

#include <cmath>

#include <Eigen/Geometry>
#include <fmt/core.h>

namespace driftless::render {

OverlayState overlay_state(const PlatformTracker& tracker) {
  OverlayState st;
  for (int i = 0; i < 2; ++i) {
    st.plat_deg[i] = tracker.angle_deg(i);
    st.moving[i] = tracker.moving(i);
  }
  st.next_flip_s = tracker.predicted_next_flip_s();
  st.next_platform = tracker.predicted_next_platform();
  return st;
}

OverlayText overlay_text(const std::string& title, double t_s, double speed, bool realtime_flip,
                         const OverlayState& st) {
  OverlayText o;
  o.top_left_titles = fmt::format("{}\ntime\nplay\nplatform 1\nplatform 2\nnext flip\nattitude err",
                                  title);
  std::string play;
  if (realtime_flip) {
    play = "x1 (flip shown in real time)";
  } else if (speed == 1.0) {
    play = "x1 real time";
  } else {
    play = fmt::format("x{:g} {}", speed, speed > 1.0 ? "time-lapse" : "slow motion");
  }
  auto plat = [&](int i) {
    if (std::isnan(st.plat_deg[i])) return std::string(st.moving[i] ? "moving" : "unknown");
    return fmt::format("{:+7.2f} deg  {}", st.plat_deg[i], st.moving[i] ? "moving" : "at rest");
  };
  std::string next = "unknown (fewer than 2 flips seen)";
  if (!std::isnan(st.next_flip_s)) {
    next = fmt::format("~{:.1f} s, platform {}", st.next_flip_s, st.next_platform + 1);
  }
  const std::string att = std::isnan(st.attitude_error_deg)
                              ? std::string("n/a (needs ref_q and the estimator)")
                              : fmt::format("{:.4f} deg (DriftLess-corrected)",
                                            st.attitude_error_deg);
  const int h = static_cast<int>(t_s / 3600.0);
  const int mi = static_cast<int>((t_s - 3600.0 * h) / 60.0);
  const double sec = t_s - 3600.0 * h - 60.0 * mi;
  o.top_left_values = fmt::format(" \n{:.2f} s  ({}:{:02d}:{:05.2f})\n{}\n{}\n{}\n{}\n{}", t_s, h,
                                  mi, sec, play, plat(0), plat(1), next, att);
  return o;
}

Eigen::Vector3d residual_dps(const Sample& s, const Eigen::Vector3d& a1,
                             const Eigen::Vector3d& a2) {
  const Eigen::Matrix3d R1 = geo::rot_about_axis_deg(a1, s.plat1_deg);
  const Eigen::Matrix3d R2 = geo::rot_about_axis_deg(a2, s.plat2_deg);
  return R1 * s.gyro1_dps - R2 * s.gyro2_dps;
}

ResidualChart::ResidualChart(const Eigen::Vector3d& a1, const Eigen::Vector3d& a2,
                             double window_s, int points)
    : a1_(a1),
      a2_(a2),
      chart_("residual R1y1-R2y2 xyz, pale: true (deg/s)",
             {{"r x", {0.95f, 0.25f, 0.25f}},
              {"r y", {0.25f, 0.85f, 0.25f}},
              {"r z", {0.35f, 0.5f, 1.0f}},
              {"true x", {1.0f, 0.7f, 0.7f}},
              {"true y", {0.7f, 1.0f, 0.7f}},
              {"true z", {0.75f, 0.8f, 1.0f}}},
             window_s),
      bucket_s_(window_s / points) {}

void ResidualChart::flush_bucket() {
  std::vector<double> v(6, kNaN);
  if (n_r_ > 0) {
    for (int k = 0; k < 3; ++k) v[k] = sum_r_[k] / n_r_;
  }
  if (n_truth_ > 0) {
    for (int k = 0; k < 3; ++k) v[3 + k] = sum_truth_[k] / n_truth_;
  }
  if (n_r_ > 0 || n_truth_ > 0) chart_.push(last_t_s_, v);
  sum_r_.setZero();
  sum_truth_.setZero();
  n_r_ = n_truth_ = 0;
}

void ResidualChart::push(const Sample& s, bool at_rest) {
  if (std::isnan(bucket_start_s_)) bucket_start_s_ = s.t_s;
  if (s.t_s - bucket_start_s_ >= bucket_s_) {
    flush_bucket();
    bucket_start_s_ = s.t_s;
  }
  last_t_s_ = s.t_s;
  if (!at_rest || !std::isfinite(s.plat1_deg) || !std::isfinite(s.plat2_deg)) return;
  if (s.gyros_finite()) {
    sum_r_ += residual_dps(s, a1_, a2_);
    ++n_r_;
  }
  if (s.true_bias1_dps.allFinite() && s.true_bias2_dps.allFinite()) {
    Sample b = s;
    b.gyro1_dps = s.true_bias1_dps;
    b.gyro2_dps = s.true_bias2_dps;
    sum_truth_ += residual_dps(b, a1_, a2_);
    ++n_truth_;
  }
}

BiasChart::BiasChart(int sensor, double window_s, int points)
    : chart_(fmt::format("bias {} estimate xyz, pale: true (deg/s)", sensor),
             {{"est x", {0.95f, 0.25f, 0.25f}},
              {"est y", {0.25f, 0.85f, 0.25f}},
              {"est z", {0.35f, 0.5f, 1.0f}},
              {"true x", {1.0f, 0.7f, 0.7f}},
              {"true y", {0.7f, 1.0f, 0.7f}},
              {"true z", {0.75f, 0.8f, 1.0f}}},
             window_s),
      bucket_s_(window_s / points) {}

void BiasChart::push(double t_s, const Eigen::Vector3d& est, const Eigen::Vector3d& truth) {
  if (!std::isnan(last_push_s_) && t_s - last_push_s_ < bucket_s_) return;
  last_push_s_ = t_s;
  chart_.push(t_s, {est[0], est[1], est[2], truth[0], truth[1], truth[2]});
}

}  // namespace driftless::render
