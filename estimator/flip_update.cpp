#include "estimator/flip_update.hpp"

#include <algorithm>
#include <cmath>

#include "estimator/clip_detector.hpp"
#include "estimator/geometry.hpp"

namespace driftless::est {

bool flip_clipped(const FlipWindow& w) {
  ClipDetector d;
  for (const FlipSample& s : w.samples()) {
    for (int i = 0; i < 3; ++i) {
      d.push(i, s.gyro1_dps[i], false);
      d.push(3 + i, s.gyro2_dps[i], false);
    }
  }
  return !d.suspected().empty();
}

FlipWindow::FlipWindow(double settle_s, double max_s, double rate_hz)
    : settle_s_(settle_s), max_s_(max_s) {
  const double rate = std::isfinite(rate_hz) && rate_hz > 0.0 ? rate_hz : 1000.0;
  capacity_ = static_cast<std::size_t>(std::ceil((max_s + settle_s) * rate * 1.25)) + 16;
  buf_.reserve(capacity_);
}

void FlipWindow::reset() {
  open_ = false;
  have_rest_ = false;
  buf_.clear();
}

void FlipWindow::remember_rest(const Sample& s, const StandstillStep& st) {
  have_rest_ = true;
  rest_t_s_ = s.t_s;
  rest_p1_deg_ = st.plat1_deg;
  rest_p2_deg_ = st.plat2_deg;
}

FlipWindow::Event FlipWindow::abort() {
  open_ = false;
  have_rest_ = false;
  buf_.clear();
  return Event::kAborted;
}

FlipWindow::Event FlipWindow::push(const Sample& s, double dt_s, const StandstillStep& st) {
  const bool r1 = st.plat1_rest, r2 = st.plat2_rest;
  const FlipSample fs{dt_s, s.gyro1_dps, s.gyro2_dps, s.accel1_mps2, s.accel2_mps2};
  if (!open_) {
    if (r1 && r2) {
      remember_rest(s, st);
      return Event::kNone;
    }
    // exactly one platform left its rest right after a sample where both rested; the other stays
    const bool one = have_rest_ && r1 != r2 && std::isfinite(dt_s);
    have_rest_ = false;
    if (!one || (r1 ? st.plat1_deg != rest_p1_deg_ : st.plat2_deg != rest_p2_deg_)) return Event::kNone;
    moving_ = r1 ? 2 : 1;
    start_deg_ = moving_ == 1 ? rest_p1_deg_ : rest_p2_deg_;
    rest_deg_ = moving_ == 1 ? rest_p2_deg_ : rest_p1_deg_;
    t_start_s_ = rest_t_s_;
    t_back_s_ = kNaN;
    buf_.clear();
    buf_.push_back(fs);
    open_ = true;
    return Event::kNone;
  }
  // the other platform must rest where it was; no gaps; not longer than max_s
  const bool other_rest = moving_ == 1 ? r2 : r1;
  const double other_deg = moving_ == 1 ? st.plat2_deg : st.plat1_deg;
  if (!other_rest || other_deg != rest_deg_ || !std::isfinite(dt_s) || buf_.size() >= capacity_ ||
      s.t_s - t_start_s_ > max_s_ + settle_s_) {
    const Event e = abort();
    if (r1 && r2) remember_rest(s, st);
    return e;
  }
  buf_.push_back(fs);
  if (!(moving_ == 1 ? r1 : r2)) {
    t_back_s_ = kNaN;  // still (or again) moving
    return Event::kNone;
  }
  if (!std::isfinite(t_back_s_)) t_back_s_ = s.t_s;
  end_deg_ = moving_ == 1 ? st.plat1_deg : st.plat2_deg;
  // the sensor's low-pass filter still releases the end of the turn for a while: integrate on
  if (s.t_s - t_back_s_ < settle_s_) return Event::kNone;
  open_ = false;
  t_end_s_ = s.t_s;
  remember_rest(s, st);  // this sample may start the next flip
  return end_deg_ != start_deg_ ? Event::kClosed : Event::kAborted;
}

namespace {

// the rate of one sensor with the estimated errors removed, (I - E)(y - b - G f), deg/s
Eigen::Vector3d corrected(const SensorErrors& e, const Eigen::Vector3d& y, const Eigen::Vector3d& f_g, bool use_g) {
  Eigen::Vector3d u = y - e.b_dps;
  if (use_g) u -= e.G_dps_per_g * f_g;
  return u - e.E_frac * u;
}

bool accel_ok(const FlipSample& k) { return k.accel1_mps2.allFinite() && k.accel2_mps2.allFinite(); }

}  // namespace

double nearest_turn_mod_360_deg(double dtheta_deg, double turn_deg) {
  if (!std::isfinite(dtheta_deg) || !std::isfinite(turn_deg)) return dtheta_deg;
  return dtheta_deg + 360.0 * std::round((turn_deg - dtheta_deg) / 360.0);
}

FlipRows flip_rows(const FlipWindow& w, const FlipModel& m) {
  FlipRows out;
  const std::vector<FlipSample>& buf = w.samples();
  if (buf.empty()) return out;
  const bool m1 = w.moving() == 1;
  const Eigen::Vector3d a = (m.M_moving_start.transpose() * m.hinge_box).normalized();  // moving sensor axes
  // the angle columns' change, taken modulo 360 below with the sign and size the gyros saw (a
  // platform that always turns one way reads +90 -> -90 where it turned +180 through +-180)
  double dtheta_deg = w.end_deg() - w.start_deg();
  const Eigen::Matrix3d C0 = m.M_moving_start.transpose() * m.M_rest;  // rest sensor -> moving sensor at start
  const Eigen::Vector3d a_s = (m.M_rest.transpose() * m.hinge_rest_box).normalized();  // rest hinge, rest sensor axes
  const auto ym = [m1](const FlipSample& k) -> const Eigen::Vector3d& { return m1 ? k.gyro1_dps : k.gyro2_dps; };
  const auto ys = [m1](const FlipSample& k) -> const Eigen::Vector3d& { return m1 ? k.gyro2_dps : k.gyro1_dps; };
  const auto fm = [m1](const FlipSample& k) -> Eigen::Vector3d { return (m1 ? k.accel1_mps2 : k.accel2_mps2) / kStandardGravityMps2; };
  const auto fs = [m1](const FlipSample& k) -> Eigen::Vector3d { return (m1 ? k.accel2_mps2 : k.accel1_mps2) / kStandardGravityMps2; };
  // pass 1: the turn about the hinge relative to the box, from the gyros (the box's own rate
  // about the hinge, a^T C u_s, does not depend on the platform angle: Rot(a, δ) keeps a)
  // G f needs the specific force of every sample; without it G is left out of the rows
  const bool use_g = m.use_g && std::all_of(buf.begin(), buf.end(), accel_ok);
  double turn_deg = 0.0;
  for (const FlipSample& k : buf) {
    const Eigen::Vector3d um = corrected(m.moving, ym(k), fm(k), use_g), us = corrected(m.rest, ys(k), fs(k), use_g);
    turn_deg += (a.dot(um) - a.dot(C0 * us)) * k.dt_s;
  }
  dtheta_deg = nearest_turn_mod_360_deg(dtheta_deg, turn_deg);
  if (!(turn_deg * dtheta_deg > 0.0) || std::fabs(dtheta_deg / turn_deg - 1.0) > 0.2) return out;
  // the profile delta(t) scaled to the angle change the rest readings give (its scale error is E_aa)
  const double lambda = dtheta_deg / turn_deg;
  // pass 2: the residual and its regressors, sample by sample (rectangle rule, the profile at
  // the middle of each sample's interval)
  double delta_deg = 0.0, span_s = 0.0, sum_dt2 = 0.0, prev_step_deg = 0.0, jump_deg = 0.0;
  Eigen::Matrix3d S_b = Eigen::Matrix3d::Zero();
  Eigen::Vector3d F_m = Eigen::Vector3d::Zero(), W_c = Eigen::Vector3d::Zero(), W_s = Eigen::Vector3d::Zero();
  for (const FlipSample& k : buf) {
    const Eigen::Vector3d um = corrected(m.moving, ym(k), fm(k), use_g), us = corrected(m.rest, ys(k), fs(k), use_g);
    const double step_deg = (a.dot(um) - a.dot(C0 * us)) * k.dt_s;
    jump_deg = std::max(jump_deg, std::fabs(step_deg - prev_step_deg));
    prev_step_deg = step_deg;
    const Eigen::Matrix3d C = geo::rot_about_axis_deg(a, -lambda * (delta_deg + 0.5 * step_deg)) * C0;
    delta_deg += step_deg;
    out.z_deg += (ym(k) - C * ys(k)) * k.dt_s;
    S_b += C * k.dt_s;
    if (use_g) {
      F_m += fm(k) * k.dt_s;
      out.H_G_rest -= matrix_error_jacobian(C, fs(k)) * k.dt_s;
    }
    W_c += C * us * k.dt_s;
    // the part of the stops' difference d_end - d_start the platform has turned through so far
    // (the profile's progress): it turns the moving frame as d_start does, but grows over the flip
    W_s += (delta_deg - 0.5 * step_deg) / turn_deg * (C * us) * k.dt_s;
    out.H_stop_rest += kRadPerDeg * (C * a_s.cross(us)) * k.dt_s;
    out.H_E_rest -= matrix_error_jacobian(C, us) * k.dt_s;
    span_s += k.dt_s;
    sum_dt2 += k.dt_s * k.dt_s;
  }
  out.z_deg -= dtheta_deg * a;
  out.H_stop_end = a - kRadPerDeg * a.cross(W_s);
  out.H_stop_start = -a - kRadPerDeg * a.cross(W_c - W_s);
  out.H_b_moving = span_s * Eigen::Matrix3d::Identity();
  out.H_b_rest = -S_b;
  if (use_g) out.H_G_moving = matrix_error_jacobian(Eigen::Matrix3d::Identity(), F_m);
  out.g_columns = use_g;
  out.H_E_moving = matrix_error_jacobian(Eigen::Matrix3d::Identity(), dtheta_deg * a + W_c);
  // white noise of both sensors (C is a rotation), and each rest angle's reading error along the hinge
  out.R_deg2 = 2.0 * m.sample_var_dps2 * sum_dt2 * Eigen::Matrix3d::Identity() +
               2.0 * m.angle_sigma_deg * m.angle_sigma_deg * a * a.transpose();
  // a sampled rate integrated by the rectangle rule: where the turn changes abruptly (an end stop
  // stops the platform within one sample), the sum misses up to half of that sample's change,
  // uniform: (largest change of the turn per sample)^2 / 12 along the hinge; the profile carries
  // the same error into C, which turns the box's rate seen meanwhile (|W_c| deg) by it across it
  const double q_deg2 = jump_deg * jump_deg / 12.0;
  const Eigen::Matrix3d across = Eigen::Matrix3d::Identity() - a * a.transpose();
  const double w_across_deg = (across * W_c).norm();
  out.R_deg2 += q_deg2 * a * a.transpose() + q_deg2 * (kRadPerDeg * w_across_deg) * (kRadPerDeg * w_across_deg) * across;
  if (m.use_g && !use_g) {
    // G_m F_m - sum C G_s f_s dt with f unread, |f| <= 1 g: per axis var(sum_j G_ij F_j) =
    // var(G) |F|^2 <= var(G) T^2 (g s)^2 for each sensor
    out.R_deg2 += 2.0 * m.g_var_dps2_per_g2 * span_s * span_s * Eigen::Matrix3d::Identity();
  }
  out.span_s = span_s;
  out.valid = out.z_deg.allFinite();
  return out;
}

}  // namespace driftless::est
