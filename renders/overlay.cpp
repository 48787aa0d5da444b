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
    st.flip_from_deg[i] = tracker.flip_from_deg(i);
  }
  st.next_flip_s = tracker.predicted_next_flip_s();
  st.next_platform = tracker.predicted_next_platform();
  return st;
}

namespace {

// the axis colours of every chart: x red, y green, z blue
constexpr float kAxisRgb[3][3] = {{0.95f, 0.3f, 0.3f}, {0.3f, 0.85f, 0.3f}, {0.4f, 0.6f, 1.0f}};

std::vector<LegendEntry> axis_legend(bool with_truth) {
  std::vector<LegendEntry> l;
  for (int k = 0; k < 3; ++k) l.push_back({std::string(1, "xyz"[k]), {kAxisRgb[k][0], kAxisRgb[k][1], kAxisRgb[k][2]}});
  if (with_truth) l.push_back({"true", {0.85f, 0.85f, 0.85f}, true});
  return l;
}

// three axis lines, then the same three dashed: the reference
std::vector<ChartLine> axis_lines(const char* name, const char* ref) {
  std::vector<ChartLine> lines;
  for (int pass = 0; pass < 2; ++pass) {
    for (int k = 0; k < 3; ++k) {
      lines.push_back({fmt::format("{} {}", pass == 0 ? name : ref, "xyz"[k]),
                       {kAxisRgb[k][0], kAxisRgb[k][1], kAxisRgb[k][2]}, pass == 1});
    }
  }
  return lines;
}

std::string clock_text(double t_s) {
  const int h = static_cast<int>(t_s / 3600.0);
  const int mi = static_cast<int>((t_s - 3600.0 * h) / 60.0);
  const double sec = t_s - 3600.0 * h - 60.0 * mi;
  return fmt::format("{:.2f} s  ({}:{:02d}:{:04.1f})", t_s, h, mi, sec);
}

std::string play_text(const PlayState& p) {
  if (p.realtime_flip) return "x1 (flip in real time)";
  if (p.speed == 1.0) return "x1 real time";
  return fmt::format("x{:g} {}", p.speed, p.speed > 1.0 ? "time-lapse" : "slow motion");
}

std::string next_flip_text(const PlayState& p, const OverlayState& st) {
  if (std::isnan(st.next_flip_s)) return "unknown (fewer than 2 flips seen)";
  if (std::isfinite(p.end_s) && st.next_flip_s > p.end_s) return fmt::format("none before the end ({:.0f} s)", p.end_s);
  return fmt::format("~{:.1f} s, platform {}", st.next_flip_s, st.next_platform + 1);
}

std::string attitude_text(const AttitudeNow& a) {
  if (!a.available) return "n/a (needs ref_q and the estimator)";
  if (!a.started) return "-  (starts when the filter has locked on)";
  return fmt::format("{:.2f} deg since lock at {:.1f} s", a.corrected_deg, a.start_s);
}

}  // namespace

std::string platform_text(const OverlayState& st, int i) {
  const double now = st.plat_deg[i], from = st.flip_from_deg[i];
  if (!st.moving[i]) {
    return std::isnan(now) ? std::string("unknown") : fmt::format("{:+.0f} deg, at rest", now);
  }
  // a flip runs from one end stop to the other: say where it comes from and where it goes
  if (std::isfinite(from) && std::abs(from) >= 1.0) {
    const std::string where = std::isnan(now) ? std::string() : fmt::format(" (now {:+.0f})", now);
    return fmt::format("{:+.0f} -> {:+.0f} deg, moving{}", from, -from, where);
  }
  return std::isnan(now) ? std::string("moving") : fmt::format("moving, now {:+.0f} deg", now);
}

std::vector<TextRow> overlay_rows(const PlayState& p, const OverlayState& st) {
  std::vector<TextRow> rows;
  rows.push_back({"time", clock_text(p.t_s) + "  " + play_text(p)});
  for (int i = 0; i < 2; ++i) {
    rows.push_back({fmt::format("platform {}", i + 1), platform_text(st, i) + (p.close_up == i ? "  [close-up]" : "")});
  }
  rows.push_back({"next flip", next_flip_text(p, st)});
  rows.push_back({"attitude error", attitude_text(st.attitude)});
  return rows;
}

Eigen::Vector3d residual_dps(const Sample& s, const Eigen::Vector3d& a1, const Eigen::Vector3d& a2) {
  const Eigen::Matrix3d R1 = geo::rot_about_axis_deg(a1, s.plat1_deg);
  const Eigen::Matrix3d R2 = geo::rot_about_axis_deg(a2, s.plat2_deg);
  return R1 * s.gyro1_dps - R2 * s.gyro2_dps;
}

ResidualChart::ResidualChart(const Eigen::Vector3d& a1, const Eigen::Vector3d& a2, double window_s, int points)
    : a1_(a1),
      a2_(a2),
      chart_("residual R1 y1 - R2 y2, deg/s", axis_lines("r", "true"), axis_legend(true), window_s, 0.02),
      bucket_s_(window_s / points) {
  chart_.empty_text = "waiting for both platforms at rest";
}

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
    : chart_(fmt::format("sensor {} bias estimate, deg/s", sensor), axis_lines("est", "true"), axis_legend(true),
             window_s, 0.02),
      bucket_s_(window_s / points) {
  chart_.empty_text = "waiting for the first filter update";
}

void BiasChart::push(double t_s, const Eigen::Vector3d& est, const Eigen::Vector3d& truth) {
  if (!std::isnan(last_push_s_) && t_s - last_push_s_ < bucket_s_) return;
  last_push_s_ = t_s;
  chart_.push(t_s, {est[0], est[1], est[2], truth[0], truth[1], truth[2]});
}

AttitudeChart::AttitudeChart(double window_s, int points)
    : chart_("attitude error since lock, deg",
             {{"DriftLess", {0.4f, 0.6f, 1.0f}}, {"bias fixed at lock", {0.95f, 0.35f, 0.3f}}},
             {{"DriftLess", {0.4f, 0.6f, 1.0f}}, {"bias fixed", {0.95f, 0.35f, 0.3f}}}, window_s, 0.1),
      bucket_s_(window_s / points) {
  chart_.empty_text = "waiting for the filter to lock";
}

void AttitudeChart::push(double t_s, const AttitudeNow& a) {
  if (!a.started) return;
  if (!std::isnan(last_push_s_) && t_s - last_push_s_ < bucket_s_) return;
  last_push_s_ = t_s;
  chart_.push(t_s, {a.corrected_deg, a.fixed_deg});
}

}  // namespace driftless::render
