#include "twin/motion.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <fmt/core.h>

#include "estimator/geometry.hpp"
#include "estimator/input_error.hpp"
#include "estimator/random.hpp"
#include "estimator/sample.hpp"
#include "importers/ground_truth.hpp"

namespace driftless::twin {
namespace {

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument(what);
}

Eigen::Quaterniond rz(double a) { return Eigen::Quaterniond(Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ())); }
Eigen::Quaterniond rx(double a) { return Eigen::Quaterniond(Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX())); }

// a function of time with its first two derivatives (value, per s, per s^2): the closed-form
// motions differentiate themselves through these operations
struct Jet {
  double v = 0, d = 0, dd = 0;
};
Jet operator+(const Jet& a, const Jet& b) { return {a.v + b.v, a.d + b.d, a.dd + b.dd}; }
Jet operator-(const Jet& a, const Jet& b) { return {a.v - b.v, a.d - b.d, a.dd - b.dd}; }
Jet operator+(const Jet& a, double c) { return {a.v + c, a.d, a.dd}; }
Jet operator+(double c, const Jet& a) { return {c + a.v, a.d, a.dd}; }
Jet operator-(const Jet& a, double c) { return {a.v - c, a.d, a.dd}; }
Jet operator-(double c, const Jet& a) { return {c - a.v, -a.d, -a.dd}; }
Jet operator*(const Jet& a, double c) { return {a.v * c, a.d * c, a.dd * c}; }
Jet operator*(double c, const Jet& a) { return {c * a.v, c * a.d, c * a.dd}; }
Jet operator/(const Jet& a, double c) { return {a.v / c, a.d / c, a.dd / c}; }
Jet operator*(const Jet& a, const Jet& b) {
  return {a.v * b.v, a.d * b.v + a.v * b.d, a.dd * b.v + 2 * a.d * b.d + a.v * b.dd};
}
Jet sin(const Jet& a) {
  const double s = std::sin(a.v), c = std::cos(a.v);
  return {s, c * a.d, c * a.dd - s * a.d * a.d};
}
Jet cos(const Jet& a) {
  const double s = std::sin(a.v), c = std::cos(a.v);
  return {c, -s * a.d, -s * a.dd - c * a.d * a.d};
}
// atan2(y(t), x) for a constant x > 0
Jet atan2_const_x(const Jet& y, double x) {
  const double den = x * x + y.v * y.v;
  return {std::atan2(y.v, x), x * y.d / den, x * y.dd / den - 2 * x * y.v * y.d * y.d / (den * den)};
}

// ---------------------------------------------------------------------------------------------
// static

class StaticMotion final : public Motion {
 public:
  explicit StaticMotion(const StaticMotionParams& p)
      : p_(p.position_m),
        q_(quat_from_ypr(p.attitude_ypr_deg[0] * kRadPerDeg, p.attitude_ypr_deg[1] * kRadPerDeg,
                         p.attitude_ypr_deg[2] * kRadPerDeg)) {}
  void pose(double, Eigen::Vector3d& p, Eigen::Quaterniond& q) const override {
    p = p_;
    q = q_;
  }
  bool is_static() const override { return true; }
  Carrier carrier() const override { return Carrier::pan_tilt; }

 private:
  Eigen::Vector3d p_;
  Eigen::Quaterniond q_;
};

// ---------------------------------------------------------------------------------------------
// pan/tilt: per axis a list of moves (trapezoidal rate profile) each followed by a dwell

struct AxisMove {
  double t0 = 0;          // move start, s
  double t_acc = 0;       // ramp duration, s
  double t_cruise = 0;    // constant-rate duration, s
  double t_end = 0;       // end of the dwell that follows, s
  double from = 0;        // rad
  double dir = 1;         // +1 / -1
  double v_peak = 0;      // rad/s
  double accel = 0;       // rad/s^2
};

// angle of one axis at t (moves sorted by t0)
double axis_angle(const std::vector<AxisMove>& moves, double t) {
  auto it = std::upper_bound(moves.begin(), moves.end(), t,
                             [](double tt, const AxisMove& m) { return tt < m.t0; });
  if (it == moves.begin()) return moves.front().from;
  const AxisMove& m = *(it - 1);
  double tau = t - m.t0;
  double s = 0;  // distance travelled, rad
  const double ta = m.t_acc, tc = m.t_cruise;
  const double d_acc = 0.5 * m.accel * ta * ta;
  if (tau <= ta) {
    s = 0.5 * m.accel * tau * tau;
  } else if (tau <= ta + tc) {
    s = d_acc + m.v_peak * (tau - ta);
  } else if (tau <= 2 * ta + tc) {
    const double u = tau - ta - tc;
    s = d_acc + m.v_peak * tc + m.v_peak * u - 0.5 * m.accel * u * u;
  } else {
    s = 2 * d_acc + m.v_peak * tc;
  }
  return m.from + m.dir * s;
}

std::vector<AxisMove> make_axis_moves(rnd::NormalStream& rng, double range_rad, double vmin, double vmax,
                                      double accel, double dwell_min, double dwell_max,
                                      double duration_s) {
  std::vector<AxisMove> moves;
  double t = 0, angle = 0;
  // start with a dwell at 0 so the run begins at rest
  t = rng.uniform(dwell_min, dwell_max);
  while (t <= duration_s + 1.0) {
    double target = rng.uniform(-range_rad, range_rad);
    if (std::abs(target - angle) < 5 * kRadPerDeg) target = angle > 0 ? angle - 0.5 * range_rad : angle + 0.5 * range_rad;
    AxisMove m;
    m.t0 = t;
    m.from = angle;
    const double dist = std::abs(target - angle);
    m.dir = target >= angle ? 1.0 : -1.0;
    m.accel = accel;
    m.v_peak = std::min(rng.uniform(vmin, vmax), std::sqrt(dist * accel));
    m.t_acc = m.v_peak / accel;
    m.t_cruise = (dist - m.v_peak * m.v_peak / accel) / m.v_peak;
    const double t_move = 2 * m.t_acc + m.t_cruise;
    m.t_end = t + t_move + rng.uniform(dwell_min, dwell_max);
    angle = m.from + m.dir * (m.v_peak * m.v_peak / accel + m.v_peak * m.t_cruise);
    t = m.t_end;
    moves.push_back(m);
  }
  if (moves.empty()) {
    AxisMove m;
    m.t0 = 0;
    moves.push_back(m);
  }
  return moves;
}

class PanTiltMotion final : public Motion {
 public:
  PanTiltMotion(const PanTiltParams& p, double duration_s, std::uint64_t seed)
      : q_mount_(quat_from_ypr(p.mount_ypr_deg[0] * kRadPerDeg, p.mount_ypr_deg[1] * kRadPerDeg,
                               p.mount_ypr_deg[2] * kRadPerDeg)) {
    rnd::NormalStream pan_rng(seed, rnd::Stream::kPanMoves), tilt_rng(seed, rnd::Stream::kTiltMoves);
    pan_ = make_axis_moves(pan_rng, p.pan_range_deg * kRadPerDeg, p.min_rate_dps * kRadPerDeg,
                           p.max_rate_dps * kRadPerDeg, p.accel_dps2 * kRadPerDeg, p.dwell_min_s,
                           p.dwell_max_s, duration_s);
    tilt_ = make_axis_moves(tilt_rng, p.tilt_range_deg * kRadPerDeg, p.min_rate_dps * kRadPerDeg,
                            p.max_rate_dps * kRadPerDeg, p.accel_dps2 * kRadPerDeg, p.dwell_min_s,
                            p.dwell_max_s, duration_s);
  }
  void pose(double t, Eigen::Vector3d& p, Eigen::Quaterniond& q) const override {
    const Eigen::Quaterniond yoke = rz(axis_angle(pan_, t)) * rx(axis_angle(tilt_, t));
    p = World::pan_tilt_axis_enu_m() + yoke * World::box_on_tilt_head_m();
    q = yoke * q_mount_;
  }
  Carrier carrier() const override { return Carrier::pan_tilt; }

 private:
  Eigen::Quaterniond q_mount_;
  std::vector<AxisMove> pan_, tilt_;
};

// ---------------------------------------------------------------------------------------------
// ground vehicle: legs of constant longitudinal acceleration or constant yaw rate

struct DriveSegment {
  double t0 = 0;        // s
  double s0 = 0;        // arc length at start, m
  Eigen::Vector2d p0 = Eigen::Vector2d::Zero();  // ENU east/north, m
  double psi0 = 0;      // heading, rad
  double v0 = 0;        // speed, m/s
  double accel = 0;     // m/s^2 (turn segments: 0)
  double yaw_rate = 0;  // rad/s (straight segments: 0)
};

struct Bump {
  double s = 0;       // start along the path, m
  double length = 0;  // m
  double height = 0;  // m
  double side = 0;    // -1..1: how much more the left wheels lift (roll)
};

class GroundVehicleMotion final : public Motion {
 public:
  GroundVehicleMotion(const GroundVehicleParams& p, double duration_s, std::uint64_t seed) : p_(p) {
    rnd::NormalStream rng(seed, rnd::Stream::kVehicleDrive);
    DriveSegment cur;
    cur.psi0 = p.heading_deg * kRadPerDeg;
    double t = 0;
    auto push = [&](double dur, double accel, double yaw_rate) {
      cur.t0 = t;
      cur.accel = accel;
      cur.yaw_rate = yaw_rate;
      segs_.push_back(cur);
      // advance the state to the end of this segment
      evaluate(segs_.back(), dur, cur.p0, cur.psi0, cur.v0, cur.s0);
      t += dur;
    };
    push(rng.uniform(2.0, 5.0), 0, 0);  // idle at the start
    while (t <= duration_s + 1.0) {
      const double v_target = rng.uniform(0.3, 1.0) * p.max_speed_mps;
      const double a = rng.uniform(0.4, 1.0) * p.max_accel_mps2;
      if (std::abs(v_target - cur.v0) > 0.1) {
        const double sgn = v_target > cur.v0 ? 1.0 : -1.0;
        push(std::abs(v_target - cur.v0) / a, sgn * a, 0);
      }
      push(rng.uniform(3.0, 15.0), 0, 0);
      const double turn = rng.uniform(20.0, 120.0) * kRadPerDeg * (rng.uniform(0, 1) < 0.5 ? -1 : 1);
      const double r = std::min(p.max_yaw_rate_dps * kRadPerDeg,
                                p.max_lateral_accel_mps2 / std::max(cur.v0, 0.1));
      push(std::abs(turn) / r, 0, turn > 0 ? r : -r);
      push(rng.uniform(2.0, 10.0), 0, 0);
      if (rng.uniform(0, 1) < p.stop_probability) {
        const double ab = rng.uniform(0.4, 1.0) * p.max_accel_mps2;
        push(cur.v0 / ab, -ab, 0);
        cur.v0 = 0;
        push(rng.uniform(2.0, 8.0), 0, 0);
      }
    }
    // bumps along the path: a Poisson process in distance
    rnd::NormalStream bump_rng(seed, rnd::Stream::kVehicleBumps);
    const double total_s = cur.s0 + 100.0;
    if (p.bumps_per_km > 0 && p.bump_height_m > 0) {
      const double mean_gap = 1000.0 / p.bumps_per_km;
      double s = 0;
      while (true) {
        s += -mean_gap * std::log(1.0 - bump_rng.uniform(0, 1));
        if (s > total_s) break;
        Bump b;
        b.s = s;
        b.length = bump_rng.uniform(1.5, 4.0);  // body-level bump as the suspension passes it on
        b.height = bump_rng.uniform(0.3, 1.0) * p.bump_height_m;
        b.side = bump_rng.uniform(-1, 1);
        bumps_.push_back(b);
        s += b.length;
      }
    }
    for (double& ph : phase_) ph = rng.uniform(0, 2 * kPi);
  }

  void pose(double t, Eigen::Vector3d& p, Eigen::Quaterniond& q) const override {
    const VehicleAngles g = angles(t);
    q = quat_from_ypr(g.yaw.v, g.pitch.v, g.roll.v);
    p = Eigen::Vector3d(g.x.v, g.y.v, g.heave.v) + q * World::box_on_vehicle_m();
  }
  // the pose's exact derivatives: the drive, road and vibration are closed forms in t, so the
  // rates and accelerations need no differencing (5 poses per call before, and a second
  // difference over 2 ms is 1.3 % low on the 32 Hz vibration)
  MotionState at(double t) const override {
    const VehicleAngles g = angles(t);
    MotionState s;
    s.q_enu_from_body = quat_from_ypr(g.yaw.v, g.pitch.v, g.roll.v);
    const Eigen::Matrix3d R = s.q_enu_from_body.toRotationMatrix();
    // body rates of the ZYX angles (yaw psi, pitch theta, roll phi) and their time derivative
    const double sf = std::sin(g.roll.v), cf = std::cos(g.roll.v);
    const double st = std::sin(g.pitch.v), ct = std::cos(g.pitch.v);
    const double f1 = g.roll.d, f2 = g.roll.dd, t1 = g.pitch.d, t2 = g.pitch.dd, y1 = g.yaw.d, y2 = g.yaw.dd;
    s.w_body_radps = Eigen::Vector3d(f1 - y1 * st, t1 * cf + y1 * ct * sf, -t1 * sf + y1 * ct * cf);
    s.dw_body_radps2 = Eigen::Vector3d(
        f2 - y2 * st - y1 * ct * t1,
        t2 * cf - t1 * sf * f1 + y2 * ct * sf - y1 * st * t1 * sf + y1 * ct * cf * f1,
        -t2 * sf - t1 * cf * f1 + y2 * ct * cf - y1 * st * t1 * cf - y1 * ct * sf * f1);
    const Eigen::Vector3d r = World::box_on_vehicle_m();
    const Eigen::Vector3d& w = s.w_body_radps;
    s.p_enu_m = Eigen::Vector3d(g.x.v, g.y.v, g.heave.v) + s.q_enu_from_body * r;
    s.v_enu_mps = Eigen::Vector3d(g.x.d, g.y.d, g.heave.d) + R * w.cross(r);
    s.a_enu_mps2 = Eigen::Vector3d(g.x.dd, g.y.dd, g.heave.dd) + R * (s.dw_body_radps2.cross(r) + w.cross(w.cross(r)));
    return s;
  }
  Carrier carrier() const override { return Carrier::vehicle; }

 private:
  // the vehicle's position (ENU east, north, up; m) and ZYX attitude angles (rad) at t
  struct VehicleAngles {
    Jet x, y, heave, yaw, pitch, roll;
  };
  VehicleAngles angles(double t) const {
    auto it = std::upper_bound(segs_.begin(), segs_.end(), t,
                               [](double tt, const DriveSegment& s) { return tt < s.t0; });
    const DriveSegment& seg = it == segs_.begin() ? segs_.front() : *(it - 1);
    VehicleAngles g;
    Jet psi, v, s;
    drive(seg, t - seg.t0, g.x, g.y, psi, v, s);
    // road bumps under the front and rear axles: heave, pitch, roll
    const double half_wb = 0.5 * p_.wheelbase_m;
    double side_f = 0, side_r = 0;
    const Jet zf = road(s + half_wb, side_f), zr = road(s - half_wb, side_r);
    g.heave = 0.5 * (zf + zr);
    g.pitch = atan2_const_x(zr - zf, p_.wheelbase_m);  // about body y: front up = nose up = negative
    g.roll = (side_f * zf + side_r * zr) / 1.6 * 0.5;
    g.yaw = psi;
    // vibration: engine at idle plus road-induced, growing with speed
    const Jet k = v.v < p_.max_speed_mps ? v / p_.max_speed_mps : Jet{1.0, 0, 0};
    const Jet amp = (p_.idle_vibration_deg + (p_.vibration_deg - p_.idle_vibration_deg) * k) * kRadPerDeg;
    const Jet T{t, 1, 0};
    const double w = 2 * kPi;
    auto wave = [&](double hz, int i) { return sin(w * hz * T + phase_[i]); };
    g.roll = g.roll + amp * (0.6 * wave(11.3, 0) + 0.4 * wave(27.1, 1));
    g.pitch = g.pitch + amp * (0.6 * wave(13.7, 2) + 0.4 * wave(31.9, 3));
    g.yaw = g.yaw + 0.3 * amp * wave(9.1, 4);
    g.heave = g.heave + p_.vibration_heave_m * k * wave(15.3, 5);
    return g;
  }
  // one segment tau s after its start (held at its start before it: no motion)
  static void drive(const DriveSegment& g, double tau, Jet& x, Jet& y, Jet& psi, Jet& v, Jet& s) {
    const double live = tau > 0 ? 1.0 : 0.0;
    tau = std::max(0.0, tau);
    if (g.yaw_rate == 0.0) {
      const double c = std::cos(g.psi0), sn = std::sin(g.psi0);
      const double v_now = g.v0 + g.accel * tau;
      const Jet ds{g.v0 * tau + 0.5 * g.accel * tau * tau, live * v_now, live * g.accel};
      psi = {g.psi0, 0, 0};
      v = {std::max(0.0, v_now), v_now > 0 ? live * g.accel : 0.0, 0};
      x = g.p0.x() + ds * c;
      y = g.p0.y() + ds * sn;
      s = g.s0 + ds;
    } else {
      psi = {g.psi0 + g.yaw_rate * tau, live * g.yaw_rate, 0};
      v = {g.v0, 0, 0};
      const double rr = g.v0 / g.yaw_rate;
      x = g.p0.x() + rr * (sin(psi) - std::sin(g.psi0));
      y = g.p0.y() + rr * (std::cos(g.psi0) - cos(psi));
      s = {g.s0 + g.v0 * tau, live * g.v0, 0};
    }
  }
  // the end state of a segment dur s long (the next segment's start)
  static void evaluate(const DriveSegment& g, double dur, Eigen::Vector2d& xy, double& psi, double& v, double& s) {
    Jet jx, jy, jpsi, jv, js;
    drive(g, dur, jx, jy, jpsi, jv, js);
    xy = Eigen::Vector2d(jx.v, jy.v);
    psi = jpsi.v;
    v = jv.v;
    s = js.v;
  }
  // road height at arc length s (raised-cosine bumps), and the bump's side factor
  Jet road(const Jet& s, double& side) const {
    side = 0;
    auto it = std::upper_bound(bumps_.begin(), bumps_.end(), s.v,
                               [](double ss, const Bump& b) { return ss < b.s; });
    if (it == bumps_.begin()) return {};
    const Bump& b = *(it - 1);
    if (s.v > b.s + b.length) return {};
    side = b.side;
    return b.height * 0.5 * (1.0 - cos(2 * kPi * (s - b.s) / b.length));
  }

  GroundVehicleParams p_;
  std::vector<DriveSegment> segs_;
  std::vector<Bump> bumps_;
  double phase_[6] = {};
};

// ---------------------------------------------------------------------------------------------
// ship

class ShipMotion final : public Motion {
 public:
  ShipMotion(const ShipParams& p, std::uint64_t seed) : p_(p) {
    rnd::NormalStream rng(seed, rnd::Stream::kShipPhases);
    for (double& ph : phase_) ph = rng.uniform(0, 2 * kPi);
  }
  void pose(double t, Eigen::Vector3d& p, Eigen::Quaterniond& q) const override {
    const double w = 2 * kPi;
    const double chi = p_.course_deg * kRadPerDeg;
    const double roll = p_.roll_amplitude_deg * kRadPerDeg * std::sin(w * t / p_.roll_period_s + phase_[0]);
    const double pitch = p_.pitch_amplitude_deg * kRadPerDeg * std::sin(w * t / p_.pitch_period_s + phase_[1]);
    const double yaw = chi + p_.yaw_amplitude_deg * kRadPerDeg * std::sin(w * t / p_.yaw_period_s + phase_[2]);
    const double heave = p_.heave_amplitude_m * std::sin(w * t / p_.heave_period_s + phase_[3]);
    const Eigen::Quaterniond q_ship = quat_from_ypr(yaw, pitch, roll);
    const Eigen::Vector3d p_ship(p_.speed_mps * t * std::cos(chi), p_.speed_mps * t * std::sin(chi), heave);
    p = p_ship + q_ship * World::box_on_ship_m();
    q = q_ship;
  }
  Carrier carrier() const override { return Carrier::ship; }

 private:
  ShipParams p_;
  double phase_[4] = {};
};

// ---------------------------------------------------------------------------------------------
// recorded trajectory: Catmull-Rom position, slerp attitude

class TrajectoryMotion final : public Motion {
 public:
  TrajectoryMotion(std::vector<TrajectoryPoint> pts, double offset_s) : pts_(std::move(pts)), offset_(offset_s) {
    require(!pts_.empty(), "trajectory: no points");
    for (std::size_t i = 1; i < pts_.size(); ++i) {
      require(pts_[i].t_s > pts_[i - 1].t_s, "trajectory: time must increase strictly");
      // keep consecutive quaternions in one hemisphere so slerp takes the short way
      if (pts_[i].q_enu_from_body.dot(pts_[i - 1].q_enu_from_body) < 0) {
        pts_[i].q_enu_from_body.coeffs() *= -1.0;
      }
    }
    for (auto& pt : pts_) pt.q_enu_from_body.normalize();
    // tangents (non-uniform central differences; one-sided at the ends)
    const std::size_t n = pts_.size();
    tangents_.assign(n, Eigen::Vector3d::Zero());
    for (std::size_t i = 0; i < n && n > 1; ++i) {
      const std::size_t a = i == 0 ? 0 : i - 1, b = i + 1 == n ? n - 1 : i + 1;
      tangents_[i] = (pts_[b].p_enu_m - pts_[a].p_enu_m) / (pts_[b].t_s - pts_[a].t_s);
    }
  }
  void pose(double t, Eigen::Vector3d& p, Eigen::Quaterniond& q) const override {
    const double tt = t + offset_;
    if (tt <= pts_.front().t_s || pts_.size() == 1) {
      p = pts_.front().p_enu_m;
      q = pts_.front().q_enu_from_body;
      return;
    }
    if (tt >= pts_.back().t_s) {
      p = pts_.back().p_enu_m;
      q = pts_.back().q_enu_from_body;
      return;
    }
    auto it = std::upper_bound(pts_.begin(), pts_.end(), tt,
                               [](double x, const TrajectoryPoint& pt) { return x < pt.t_s; });
    const std::size_t i = static_cast<std::size_t>(it - pts_.begin()) - 1;
    const TrajectoryPoint& a = pts_[i];
    const TrajectoryPoint& b = pts_[i + 1];
    const double h = b.t_s - a.t_s;
    const double u = (tt - a.t_s) / h;
    // cubic Hermite basis
    const double u2 = u * u, u3 = u2 * u;
    const double h00 = 2 * u3 - 3 * u2 + 1, h10 = u3 - 2 * u2 + u, h01 = -2 * u3 + 3 * u2, h11 = u3 - u2;
    p = h00 * a.p_enu_m + h10 * h * tangents_[i] + h01 * b.p_enu_m + h11 * h * tangents_[i + 1];
    q = a.q_enu_from_body.slerp(u, b.q_enu_from_body);
  }
  Carrier carrier() const override { return Carrier::none; }

 private:
  std::vector<TrajectoryPoint> pts_;
  std::vector<Eigen::Vector3d> tangents_;
  double offset_ = 0;
};

std::vector<std::string> split_csv(const std::string& line) {
  std::vector<std::string> out;
  std::string cur;
  std::istringstream in(line);
  while (std::getline(in, cur, ',')) {
    while (!cur.empty() && (cur.back() == '\r' || cur.back() == ' ')) cur.pop_back();
    while (!cur.empty() && cur.front() == ' ') cur.erase(cur.begin());
    out.push_back(cur);
  }
  return out;
}

}  // namespace

Eigen::Quaterniond quat_from_ypr(double yaw_rad, double pitch_rad, double roll_rad) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()) *
                            Eigen::AngleAxisd(pitch_rad, Eigen::Vector3d::UnitY()) *
                            Eigen::AngleAxisd(roll_rad, Eigen::Vector3d::UnitX()));
}

MotionState Motion::at(double t) const {
  MotionState s;
  pose(t, s.p_enu_m, s.q_enu_from_body);
  if (is_static()) return s;
  constexpr double h = 1e-4;  // rates
  constexpr double H = 2e-3;  // accelerations (larger: round-off of a second difference)
  Eigen::Vector3d pp, pm, pP, pM;
  Eigen::Quaterniond qp, qm, qP, qM;
  pose(t + h, pp, qp);
  pose(t - h, pm, qm);
  pose(t + H, pP, qP);
  pose(t - H, pM, qM);
  s.v_enu_mps = (pp - pm) / (2 * h);
  s.w_body_radps = geo::rotvec_rad(qm.conjugate() * qp) / (2 * h);
  s.a_enu_mps2 = (pP - 2 * s.p_enu_m + pM) / (H * H);
  const Eigen::Vector3d w_ahead = geo::rotvec_rad(s.q_enu_from_body.conjugate() * qP) / H;
  const Eigen::Vector3d w_behind = geo::rotvec_rad(qM.conjugate() * s.q_enu_from_body) / H;
  s.dw_body_radps2 = (w_ahead - w_behind) / H;
  return s;
}

const char* motion_type_name(MotionType t) {
  switch (t) {
    case MotionType::static_box: return "static";
    case MotionType::pan_tilt: return "pan_tilt";
    case MotionType::ground_vehicle: return "ground_vehicle";
    case MotionType::ship: return "ship";
    case MotionType::csv: return "csv";
  }
  return "static";
}

void StaticMotionParams::validate() const {
  require(attitude_ypr_deg.allFinite(), "motion.attitude_ypr_deg must be finite (deg)");
  require(position_m.allFinite(), "motion.position_m must be finite (m)");
}

void PanTiltParams::validate() const {
  require(max_rate_dps > 0 && max_rate_dps <= 360, "motion.max_rate_dps must be in (0, 360] deg/s");
  require(min_rate_dps > 0 && min_rate_dps <= max_rate_dps, "motion.min_rate_dps must be in (0, max_rate_dps] deg/s");
  require(accel_dps2 > 0, "motion.accel_dps2 must be > 0 deg/s^2");
  require(pan_range_deg >= 5 && pan_range_deg <= 180, "motion.pan_range_deg must be in [5, 180] deg");
  require(tilt_range_deg >= 5 && tilt_range_deg <= 90, "motion.tilt_range_deg must be in [5, 90] deg");
  require(dwell_min_s >= 0 && dwell_max_s >= dwell_min_s, "motion.dwell_min_s/dwell_max_s must satisfy 0 <= min <= max (s)");
  require(mount_ypr_deg.allFinite(), "motion.mount_ypr_deg must be finite (deg)");
}

void GroundVehicleParams::validate() const {
  require(max_speed_mps > 0 && max_speed_mps <= 80, "motion.max_speed_mps must be in (0, 80] m/s");
  require(max_accel_mps2 > 0 && max_accel_mps2 <= 15, "motion.max_accel_mps2 must be in (0, 15] m/s^2");
  require(max_yaw_rate_dps > 0 && max_yaw_rate_dps <= 180, "motion.max_yaw_rate_dps must be in (0, 180] deg/s");
  require(max_lateral_accel_mps2 > 0, "motion.max_lateral_accel_mps2 must be > 0 m/s^2");
  require(stop_probability >= 0 && stop_probability <= 1, "motion.stop_probability must be in [0, 1]");
  require(bumps_per_km >= 0, "motion.bumps_per_km must be >= 0 (1/km)");
  require(bump_height_m >= 0 && bump_height_m <= 0.5, "motion.bump_height_m must be in [0, 0.5] m");
  require(wheelbase_m > 0.5 && wheelbase_m < 10, "motion.wheelbase_m must be in (0.5, 10) m");
  require(vibration_deg >= 0 && idle_vibration_deg >= 0 && vibration_heave_m >= 0,
          "motion.vibration_deg / idle_vibration_deg / vibration_heave_m must be >= 0");
  require(std::isfinite(heading_deg), "motion.heading_deg must be finite (deg)");
}

void ShipParams::validate() const {
  require(speed_mps >= 0 && speed_mps <= 30, "motion.speed_mps must be in [0, 30] m/s");
  require(std::isfinite(course_deg), "motion.course_deg must be finite (deg)");
  for (double a : {roll_amplitude_deg, pitch_amplitude_deg, yaw_amplitude_deg}) {
    require(a >= 0 && a <= 45, "motion.*_amplitude_deg must be in [0, 45] deg");
  }
  require(heave_amplitude_m >= 0 && heave_amplitude_m <= 10, "motion.heave_amplitude_m must be in [0, 10] m");
  for (double T : {roll_period_s, pitch_period_s, yaw_period_s, heave_period_s}) {
    require(T >= 0.5, "motion.*_period_s must be >= 0.5 s");
  }
}

void CsvMotionParams::validate() const {
  require(!file.empty(), "motion.file: a csv motion needs a trajectory file (t, px..pz, qw..qz or EuRoC)");
  require(std::isfinite(time_offset_s), "motion.time_offset_s must be finite (s)");
}

void MotionConfig::validate() const {
  switch (type) {
    case MotionType::static_box: static_box.validate(); break;
    case MotionType::pan_tilt: pan_tilt.validate(); break;
    case MotionType::ground_vehicle: ground_vehicle.validate(); break;
    case MotionType::ship: ship.validate(); break;
    case MotionType::csv: csv.validate(); break;
  }
}

namespace {

// EuRoC / Vicon ground truth: the importers' reader (stamps as whole ns), times from the first
// stamp formed in integers, so a 1.4e18 ns stamp keeps its last digit
std::vector<TrajectoryPoint> read_euroc_trajectory(const std::filesystem::path& path) {
  const importers::GroundTruth gt = importers::read_ground_truth(path);
  const std::int64_t t0_ns = gt.poses.front().t_ns;
  std::vector<TrajectoryPoint> pts;
  pts.reserve(gt.poses.size());
  for (const importers::PoseStamp& p : gt.poses) {
    TrajectoryPoint pt;
    pt.t_s = static_cast<double>(p.t_ns - t0_ns) * 1e-9;
    pt.p_enu_m = p.p_ref_m;
    pt.q_enu_from_body = p.q_ref_from_body;
    pts.push_back(pt);
  }
  return pts;
}

// true when the first line that is not blank starts with EuRoC's "#timestamp" header
bool is_euroc_layout(std::istream& in) {
  std::string line;
  while (std::getline(in, line)) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    return line.rfind("#timestamp", 0) == 0;
  }
  return false;
}

}  // namespace

std::vector<TrajectoryPoint> read_trajectory_csv(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path.string(), 0, "", "cannot open trajectory file");
  if (is_euroc_layout(in)) return read_euroc_trajectory(path);
  in.clear();
  in.seekg(0);
  std::string line;
  std::size_t line_no = 0;
  int idx[8] = {-1, -1, -1, -1, -1, -1, -1, -1};  // t, px, py, pz, qw, qx, qy, qz
  bool have_header = false;
  std::vector<TrajectoryPoint> pts;
  const char* names[8] = {"t", "px", "py", "pz", "qw", "qx", "qy", "qz"};
  const auto fail = [&](const std::string& what) { throw InputError(path.string(), line_no, "", what); };
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    if (!have_header) {
      if (line[0] == '#') continue;
      const auto cols = split_csv(line);
      for (std::size_t c = 0; c < cols.size(); ++c) {
        std::string name = cols[c];
        if (name.rfind("ref_", 0) == 0) name = name.substr(4);  // a driftless log works too
        if (name == "t_s") name = "t";
        for (int k = 0; k < 8; ++k) {
          if (name == names[k]) idx[k] = static_cast<int>(c);
        }
      }
      for (int k = 0; k < 8; ++k) {
        if (idx[k] < 0) {
          fail(std::string("trajectory header lacks column '") + names[k] +
               "' (expected t, px, py, pz, qw, qx, qy, qz or the EuRoC "
               "'#timestamp [ns], p_RS_R_x [m], ...' layout)");
        }
      }
      have_header = true;
      continue;
    }
    if (line[0] == '#') continue;
    const auto cols = split_csv(line);
    double v[8];
    for (int k = 0; k < 8; ++k) {
      const auto c = static_cast<std::size_t>(idx[k]);
      if (c >= cols.size()) fail("row has too few fields");
      try {
        std::size_t used = 0;
        v[k] = std::stod(cols[c], &used);
        if (used != cols[c].size()) throw std::invalid_argument("junk");
      } catch (const std::exception&) {
        fail(std::string("column '") + names[k] + "': expected a number, got '" + cols[c] + "'");
      }
    }
    TrajectoryPoint pt;
    pt.t_s = v[0];
    pt.p_enu_m = Eigen::Vector3d(v[1], v[2], v[3]);
    pt.q_enu_from_body = Eigen::Quaterniond(v[4], v[5], v[6], v[7]);
    const double n = pt.q_enu_from_body.norm();
    if (!(n > 0.5 && n < 1.5)) {
      fail("quaternion norm " + fmt::format("{:.4g}", n) +
           " is not close to 1 (qw, qx, qy, qz expected, scalar first)");
    }
    pt.q_enu_from_body.normalize();
    if (!pts.empty() && !(pt.t_s > pts.back().t_s)) {
      fail("time " + fmt::format("{:.9f}", pt.t_s) + " s does not increase (previous " +
           fmt::format("{:.9f}", pts.back().t_s) + " s)");
    }
    pts.push_back(pt);
  }
  if (pts.size() < 2) throw InputError(path.string(), 0, "", "a trajectory needs at least 2 rows");
  return pts;
}

std::unique_ptr<Motion> make_trajectory_motion(std::vector<TrajectoryPoint> points, double time_offset_s) {
  return std::make_unique<TrajectoryMotion>(std::move(points), time_offset_s);
}

std::unique_ptr<Motion> make_motion(const MotionConfig& cfg, double duration_s, std::uint64_t seed,
                                    const std::filesystem::path& base_dir) {
  cfg.validate();
  switch (cfg.type) {
    case MotionType::static_box: return std::make_unique<StaticMotion>(cfg.static_box);
    case MotionType::pan_tilt: return std::make_unique<PanTiltMotion>(cfg.pan_tilt, duration_s, seed);
    case MotionType::ground_vehicle:
      return std::make_unique<GroundVehicleMotion>(cfg.ground_vehicle, duration_s, seed);
    case MotionType::ship: return std::make_unique<ShipMotion>(cfg.ship, seed);
    case MotionType::csv: {
      std::filesystem::path f = cfg.csv.file;
      if (f.is_relative() && !base_dir.empty()) f = base_dir / f;
      return make_trajectory_motion(read_trajectory_csv(f), cfg.csv.time_offset_s);
    }
  }
  throw std::logic_error("unknown motion type");
}

}  // namespace driftless::twin
