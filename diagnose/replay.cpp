#include "diagnose/replay.hpp"

#include "estimator/geometry.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <Eigen/Dense>
#include <fmt/core.h>

namespace driftless::diagnose {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// the columns a replay needs, kept compact (a 1 h log at 100 Hz is 360k rows)
struct Raw {
  double t = kNaN;
  Eigen::Vector3d g[2];
  double plat[2] = {kNaN, kNaN};
  Eigen::Vector4d q = Eigen::Vector4d::Constant(kNaN);
  Eigen::Vector3d p = Eigen::Vector3d::Constant(kNaN);
  Eigen::Vector3d a[2];
  double temp[2] = {kNaN, kNaN};
};

Raw to_raw(const Sample& s) {
  Raw r;
  r.t = s.t_s;
  r.g[0] = s.gyro1_dps;
  r.g[1] = s.gyro2_dps;
  r.plat[0] = s.plat1_deg;
  r.plat[1] = s.plat2_deg;
  r.q = s.ref_q_wxyz;
  r.p = s.ref_p_enu_m;
  r.a[0] = s.accel1_mps2;
  r.a[1] = s.accel2_mps2;
  r.temp[0] = s.temp1_c;
  r.temp[1] = s.temp2_c;
  return r;
}

double lerp(double a, double b, double u) { return a + (b - a) * u; }

// linear interpolation of every column onto a uniform grid at rate_hz (quaternions: nlerp)
std::vector<Raw> resample(const std::vector<Raw>& in, double rate_hz) {
  std::vector<Raw> out;
  if (in.size() < 2) return in;
  const double t0 = in.front().t, t1 = in.back().t;
  const auto n = static_cast<std::size_t>(std::floor((t1 - t0) * rate_hz + 1e-9)) + 1;
  out.reserve(n);
  std::size_t j = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const double t = t0 + static_cast<double>(k) / rate_hz;
    while (j + 2 < in.size() && in[j + 1].t <= t) ++j;
    const Raw& a = in[j];
    const Raw& b = in[j + 1];
    const double u = std::clamp((t - a.t) / (b.t - a.t), 0.0, 1.0);
    Raw r;
    r.t = t;
    for (int s = 0; s < 2; ++s) {
      r.g[s] = a.g[s] + (b.g[s] - a.g[s]) * u;
      r.a[s] = a.a[s] + (b.a[s] - a.a[s]) * u;
      r.plat[s] = lerp(a.plat[s], b.plat[s], u);
      r.temp[s] = lerp(a.temp[s], b.temp[s], u);
    }
    Eigen::Vector4d qb = b.q;
    if (a.q.dot(qb) < 0) qb = -qb;
    r.q = (a.q + (qb - a.q) * u);
    if (r.q.allFinite()) r.q.normalize();
    r.p = a.p + (b.p - a.p) * u;
    out.push_back(r);
  }
  return out;
}

// median sample interval, s
double median_dt(const std::vector<Raw>& raw) {
  std::vector<double> dt;
  dt.reserve(raw.size());
  for (std::size_t k = 1; k < raw.size(); ++k) dt.push_back(raw[k].t - raw[k - 1].t);
  if (dt.empty()) return kNaN;
  auto mid = dt.begin() + static_cast<std::ptrdiff_t>(dt.size() / 2);
  std::nth_element(dt.begin(), mid, dt.end());
  return *mid;
}

// largest swing of a sensor's output inside rest intervals of both platforms, deg/s
double largest_rest_swing_dps(const std::vector<Raw>& raw, double fs) {
  // a running median over 1 s suppresses noise; the swing is the spread of that median
  // between consecutive platform flips (a static box only sees bias + Earth rate there)
  const auto w = static_cast<std::size_t>(std::max(1.0, std::round(fs)));
  double worst = 0.0;
  std::size_t seg_start = 0;
  auto same_rest = [&](std::size_t a, std::size_t b) {
    for (int s = 0; s < 2; ++s) {
      if (!std::isfinite(raw[a].plat[s]) || !std::isfinite(raw[b].plat[s])) return false;
      if (std::abs(raw[a].plat[s] - raw[b].plat[s]) > 0.5) return false;
    }
    return true;
  };
  for (std::size_t k = 1; k <= raw.size(); ++k) {
    if (k < raw.size() && same_rest(seg_start, k)) continue;
    // segment [seg_start, k): block medians of each axis
    for (int s = 0; s < 2; ++s) {
      for (int ax = 0; ax < 3; ++ax) {
        double lo = kInf, hi = -kInf;
        std::vector<double> buf;
        for (std::size_t b = seg_start; b + w <= k; b += w) {
          buf.clear();
          for (std::size_t i = b; i < b + w; ++i) {
            if (std::isfinite(raw[i].g[s][ax])) buf.push_back(raw[i].g[s][ax]);
          }
          if (buf.empty()) continue;
          auto mid = buf.begin() + static_cast<std::ptrdiff_t>(buf.size() / 2);
          std::nth_element(buf.begin(), mid, buf.end());
          lo = std::min(lo, *mid);
          hi = std::max(hi, *mid);
        }
        if (hi >= lo) worst = std::max(worst, hi - lo);
      }
    }
    seg_start = k;
  }
  return worst;
}

// a maximally flat central differentiator: x'(t_k) ~ sum_{j=1..M} d_j (x_{k+j} - x_{k-j}) / h,
// exact for polynomials of degree 2M (sum_j d_j j^(2n+1) = 1/2 for n = 0, 0 for n = 1..M-1).
// With M = 8 its response is flat to 1e-9 at 0.1 fs, 1e-4 at 0.2 fs, 1 % at 0.3 fs
std::vector<double> central_differentiator() {
  constexpr int M = 8;
  Eigen::MatrixXd A(M, M);
  for (int n = 0; n < M; ++n)
    for (int j = 1; j <= M; ++j) A(n, j - 1) = std::pow(static_cast<double>(j), 2 * n + 1);
  const Eigen::VectorXd d = A.fullPivLu().solve(0.5 * Eigen::VectorXd::Unit(M, 0));
  return std::vector<double>(d.data(), d.data() + M);
}

// what the log's header says: columns present, hinge axes, platform read-back
void read_header(const log::Metadata& meta, std::uint32_t fields, Replay& out) {
  out.meta = meta;
  out.has_ref_q = (fields & kFieldRefQ) != 0;
  out.has_ref_p = (fields & kFieldRefP) != 0;
  out.has_accel = (fields & kFieldAccel) != 0;
  out.has_temp = (fields & kFieldTemp) != 0;
  out.encoder_readback = meta.get("platform_readback").value_or("") == "encoder";
  out.hinge_axis[0] = meta.hinge1_axis().normalized();
  out.hinge_axis[1] = meta.hinge2_axis().normalized();
  out.sensors = (fields & kLayoutSingleSensor) != 0 ? 1 : 2;
}

// the single-sensor form: one IMU fixed to the body (or on platform 1) against motion capture.
// Without ref_q there is nothing to compare it with (a static body's Earth rate alone cannot
// tell a scale or cross-axis error from the turn-on bias). There is no second platform: it is
// held at 0 deg (no flips) so that only sensor 1's samples decide what is usable
void single_sensor(std::vector<Raw>& raw, Replay& out) {
  if (out.sensors != 1) return;
  if (!out.has_ref_q) {
    throw std::runtime_error(fmt::format(
        "{}: a single-sensor log ('sensors: 1') without ref_q (ref_qw, ref_qx, ref_qy, ref_qz); compare and diagnose "
        "need the body's reference attitude to predict one IMU (join motion capture or a trajectory with "
        "'driftless convert --ref'; docs/log-format.md)", out.log_path));
  }
  for (Raw& r : raw) r.plat[1] = 0.0;
  out.notes.push_back("a single-sensor log: one IMU against the reference attitude (ref_q); the sensor-2 channels, "
                      "platform flips and end stops take no part");
}

// the sample rate: metadata, else the median interval; resampled when asked
void set_rate(std::vector<Raw>& raw, const ReplayOptions& opt, Replay& out) {
  const double dt_med = median_dt(raw);
  double fs = out.meta.sample_rate_hz();
  if (!std::isfinite(fs) || fs <= 0) {
    fs = 1.0 / dt_med;
    out.notes.push_back(fmt::format("the log states no sample_rate_hz; {:.3f} Hz taken from the median sample interval", fs));
  } else if (std::abs(1.0 / dt_med - fs) > 0.01 * fs) {
    out.notes.push_back(fmt::format("the log says sample_rate_hz {:.3f} but its median interval gives {:.3f} Hz; the "
                                    "interval is used", fs, 1.0 / dt_med));
    fs = 1.0 / dt_med;
  }
  out.log_rate_hz = fs;
  if (std::isfinite(opt.resample_hz) && std::abs(fs - opt.resample_hz) > 0.01 * opt.resample_hz) {
    raw = resample(raw, opt.resample_hz);
    out.resampled = true;
    out.notes.push_back(fmt::format("the log ({:.3f} Hz) was resampled to {:.3f} Hz by linear interpolation", fs, opt.resample_hz));
    fs = opt.resample_hz;
  }
  out.sample_rate_hz = fs;
}

// attitude: ref_q, or (static logs only) identity with the Earth rate as the only rate
void check_attitude(std::vector<Raw>& raw, const ReplayOptions& opt, Replay& out) {
  if (!out.has_ref_q) {
    const double swing = largest_rest_swing_dps(raw, out.sample_rate_hz);
    if (swing > opt.static_rate_limit_dps) {
      throw std::runtime_error(fmt::format(
          "{}: the log has no reference motion (ref_qw, ref_qx, ref_qy, ref_qz) but the box moves (the gyro output swings "
          "by {:.2f} deg/s while both platforms rest); compare needs ref_q (and ref_p for accelerations) to replay a "
          "moving box (docs/log-format.md)", out.log_path, swing));
    }
    for (auto& r : raw) r.q = Eigen::Vector4d(1, 0, 0, 0);
    out.notes.push_back("the log has no ref_q: the box is assumed static and level with body axes = ENU (identity "
                        "attitude), so the body rate is the Earth rate only");
  }
  for (auto& r : raw) {
    if (!r.q.allFinite() || r.q.norm() < 0.5) {
      throw std::runtime_error(fmt::format("{}: ref_q at t = {:.6f} s is empty or not a unit quaternion", out.log_path, r.t));
    }
    r.q.normalize();
  }
}

Eigen::Quaterniond quat(const Raw& r) { return Eigen::Quaterniond(r.q[0], r.q[1], r.q[2], r.q[3]); }

// a kink of the rate (a motion profile starting or ending an acceleration) is not band limited:
// no stencil rebuilds the rate near it. It shows as an isolated spike of the second difference
// of the interval means; continuous vibration raises them everywhere and is not a kink (the FIR
// rebuilds it)
void mark_kinks(const std::vector<Eigen::Vector3d>& mean_rate, std::size_t fir_half, const ReplayOptions& opt, Replay& out) {
  const std::size_t n = out.size();
  const double limit = opt.replay_error_limit_dps * kRadPerDeg;
  std::vector<double> d2(n, 0.0), csum(n + 1, 0.0);
  for (std::size_t k = 1; k + 1 < mean_rate.size(); ++k) {
    d2[k] = (mean_rate[k + 1] - 2.0 * mean_rate[k] + mean_rate[k - 1]).cwiseAbs().maxCoeff();
  }
  for (std::size_t k = 0; k < n; ++k) csum[k + 1] = csum[k] + d2[k];
  const auto half = static_cast<std::size_t>(std::max(5.0, std::round(0.5 * out.sample_rate_hz)));
  const auto spread = static_cast<std::size_t>(std::ceil(opt.rough_guard_s * out.sample_rate_hz)) + fir_half;
  out.rough.assign(n, 0);
  for (std::size_t k = 1; k + 1 < n; ++k) {
    if (d2[k] <= limit) continue;
    const std::size_t lo = k >= half ? k - half : 0, hi = std::min(n, k + half + 1);
    const double local = (csum[hi] - csum[lo] - d2[k]) / static_cast<double>(hi - lo - 1);
    if (d2[k] <= opt.kink_ratio * local) continue;
    const std::size_t a = k >= spread ? k - spread : 0, b = std::min(n - 1, k + spread + 1);
    for (std::size_t i = a; i <= b; ++i) out.rough[i] = 1;
  }
  const auto rough_count = static_cast<std::size_t>(std::count(out.rough.begin(), out.rough.end(), 1));
  if (rough_count == 0) return;
  out.notes.push_back(fmt::format(
      "{} samples ({:.1f} %) near kinks of the reference rate (a motion profile's acceleration steps), where the rate "
      "cannot be rebuilt from ref_q to within {:.3g} deg/s, are left out of the fits",
      rough_count, 100.0 * static_cast<double>(rough_count) / static_cast<double>(n), opt.replay_error_limit_dps));
}

// body rate relative to ENU from the attitude: q' = q (0, w/2) for q = q_enu_from_body, so
// w = 2 vec(q* q'), with q' from a maximally flat central differentiator over the (sign-
// continuous) quaternions. Exact to high order for any smooth motion, rotations about moving axes
// included (rotation vectors of interval increments lose the coning term: a false 0.02 % scale
// on a 1.5 Hz two-axis wobble at 100 Hz). Near the ends, central differences. The Earth rate is
// added in body axes; the transport rate (v/R) is neglected.
void body_rate(const std::vector<Raw>& raw, const Eigen::Vector3d& earth_enu, const ReplayOptions& opt, Replay& out) {
  const std::size_t n = raw.size();
  out.t_s.resize(n);
  std::vector<Eigen::Vector4d> q(n);
  for (std::size_t k = 0; k < n; ++k) {
    out.t_s[k] = raw[k].t;
    q[k] = raw[k].q;
    if (k > 0 && q[k].dot(q[k - 1]) < 0) q[k] = -q[k];  // one hemisphere: q and -q are one rotation
  }
  const std::vector<double> d = central_differentiator();
  const auto M = d.size();
  out.w_body_radps.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    Eigen::Vector4d dq = Eigen::Vector4d::Zero();
    if (k >= M && k + M < n) {
      const double h = (out.t_s[k + M] - out.t_s[k - M]) / static_cast<double>(2 * M);
      for (std::size_t j = 1; j <= M; ++j) dq += d[j - 1] * (q[k + j] - q[k - j]);
      dq /= h;
    } else {
      const std::size_t a = k == 0 ? 0 : k - 1, b = k + 1 < n ? k + 1 : n - 1;
      dq = (q[b] - q[a]) / (out.t_s[b] - out.t_s[a]);
    }
    const Eigen::Quaterniond qk(q[k][0], q[k][1], q[k][2], q[k][3]), dqk(dq[0], dq[1], dq[2], dq[3]);
    const Eigen::Vector3d w_eb = 2.0 * (qk.conjugate() * dqk).vec();
    out.w_body_radps[k] = w_eb + qk.conjugate() * earth_enu;
  }
  // kinks from the interval mean rates (their second differences)
  std::vector<Eigen::Vector3d> mean_rate(n - 1);
  for (std::size_t k = 0; k + 1 < n; ++k) {
    mean_rate[k] = geo::rotvec_rad(quat(raw[k]).conjugate() * quat(raw[k + 1])) / (out.t_s[k + 1] - out.t_s[k]);
  }
  mark_kinks(mean_rate, M, opt, out);
  // the first and last M samples have no full differentiator stencil: left out like a kink
  for (std::size_t k = 0; k < std::min(n, M); ++k) out.rough[k] = out.rough[n - 1 - k] = 1;
}

// specific force in body axes: second differences of ref_p, else gravity only
void specific_force(const std::vector<Raw>& raw, Replay& out) {
  const std::size_t n = raw.size();
  bool p_ok = out.has_ref_p;
  if (p_ok) {
    for (const auto& r : raw) p_ok = p_ok && r.p.allFinite();
    if (!p_ok) out.notes.push_back("ref_p has empty values; accelerations set to zero");
  }
  const Eigen::Vector3d g_enu(0, 0, kStandardGravityMps2);  // f = a - g, g = (0,0,-9.81)
  out.f_body_mps2.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    Eigen::Vector3d a_enu = Eigen::Vector3d::Zero();
    if (p_ok && k > 0 && k + 1 < n) {
      const double h1 = out.t_s[k] - out.t_s[k - 1], h2 = out.t_s[k + 1] - out.t_s[k];
      a_enu = 2.0 * ((raw[k + 1].p - raw[k].p) / h2 - (raw[k].p - raw[k - 1].p) / h1) / (h1 + h2);
    }
    out.f_body_mps2[k] = quat(raw[k]).conjugate() * (a_enu + g_enu);
  }
  if (!out.has_accel && !p_ok) {
    out.notes.push_back("no ref_p and no accel columns: the specific force is gravity alone (vehicle accelerations unknown)");
  }
  if (out.has_accel) out.notes.push_back("the specific force on each sensor is taken from the log's accel columns");
}

// platforms: angle as logged, rate by central differences; unknown angle = moving
std::array<std::vector<std::uint8_t>, 2> platform_motion(const std::vector<Raw>& raw, const ReplayOptions& opt, Replay& out) {
  const std::size_t n = raw.size();
  std::array<std::vector<std::uint8_t>, 2> moving;
  for (int s = 0; s < 2; ++s) {
    out.plat_deg[s].resize(n);
    out.plat_rate_dps[s].resize(n);
    out.temp_c[s].resize(n);
    moving[s].assign(n, 0);
    for (std::size_t k = 0; k < n; ++k) {
      out.plat_deg[s][k] = raw[k].plat[s];
      out.temp_c[s][k] = out.has_temp ? raw[k].temp[s] : kNaN;
      const std::size_t a = k == 0 ? 0 : k - 1, b = k + 1 < n ? k + 1 : n - 1;
      out.plat_rate_dps[s][k] = std::isfinite(raw[k].plat[s]) ? (raw[b].plat[s] - raw[a].plat[s]) / (out.t_s[b] - out.t_s[a]) : kNaN;
      const double r = out.plat_rate_dps[s][k];
      moving[s][k] = !std::isfinite(r) || std::abs(r) > opt.flip_rate_threshold_dps;
    }
  }
  // flips: a platform turning or unknown; guard a few samples around it
  out.flipping.assign(n, 0);
  const auto guard = static_cast<std::size_t>(std::ceil(opt.flip_guard_s * out.sample_rate_hz));
  for (std::size_t k = 0; k < n; ++k) {
    if (!(moving[0][k] || moving[1][k])) continue;
    const std::size_t a = k >= guard ? k - guard : 0, b = std::min(n - 1, k + guard);
    for (std::size_t i = a; i <= b; ++i) out.flipping[i] = 1;
  }
  return moving;
}

// per platform: time since it last stopped, the direction it went, the side it rests on
void flip_history(const std::vector<Raw>& raw, const std::array<std::vector<std::uint8_t>, 2>& moving, Replay& out) {
  const std::size_t n = raw.size();
  for (int s = 0; s < 2; ++s) {
    out.since_flip_s[s].assign(n, std::numeric_limits<float>::infinity());
    out.last_flip_dir[s].assign(n, 0);
    out.rest_side[s].assign(n, 0);
    double stop_t = kInf, start_angle = kNaN;
    int dir = 0;
    bool was_moving = false;
    for (std::size_t k = 0; k < n; ++k) {
      if (moving[s][k]) {
        if (!was_moving) start_angle = k > 0 ? raw[k - 1].plat[s] : kNaN;  // the last known angle before the move
        was_moving = true;
        continue;
      }
      if (was_moving) {
        stop_t = out.t_s[k];
        const double end_angle = raw[k].plat[s];
        dir = (std::isfinite(start_angle) && std::isfinite(end_angle)) ? (end_angle > start_angle ? 1 : -1) : 0;
        was_moving = false;
      }
      if (std::isfinite(stop_t)) {
        out.since_flip_s[s][k] = static_cast<float>(out.t_s[k] - stop_t);
        out.last_flip_dir[s][k] = static_cast<std::int8_t>(dir);
      }
      const double ang = raw[k].plat[s];
      if (std::isfinite(ang) && std::abs(ang) > 1.0) out.rest_side[s][k] = ang > 0 ? 1 : -1;
    }
  }
}

// each sensor's ideal output (docs/log-format.md): y_i = R_i^T w_body + thetadot_i a_i
void sensor_truth(const std::vector<Raw>& raw, const Eigen::Vector3d& dearth_dlat_enu, Replay& out) {
  const std::size_t n = raw.size();
  out.usable.assign(n, 1);
  for (int s = 0; s < 2; ++s) {
    out.gyro_dps[s].resize(n);
    out.w_radps[s].resize(n);
    out.f_mps2[s].resize(n);
    out.dw_dlat_radps[s].resize(n);
    const Eigen::Vector3d& axis = out.hinge_axis[s];
    for (std::size_t k = 0; k < n; ++k) {
      out.gyro_dps[s][k] = raw[k].g[s];
      const double ang = raw[k].plat[s];
      if (!std::isfinite(ang)) {
        out.w_radps[s][k].setConstant(kNaN);
        out.f_mps2[s][k].setConstant(kNaN);
        out.dw_dlat_radps[s][k].setConstant(kNaN);
        out.usable[k] = 0;
        continue;
      }
      const Eigen::Matrix3d Rt = geo::rot_about_axis_deg(axis, ang).transpose();
      const double rate = out.plat_rate_dps[s][k];
      out.w_radps[s][k] = Rt * out.w_body_radps[k] + (std::isfinite(rate) ? rate : 0.0) * kRadPerDeg * axis;
      out.f_mps2[s][k] = out.has_accel && raw[k].a[s].allFinite() ? raw[k].a[s] : Eigen::Vector3d(Rt * out.f_body_mps2[k]);
      out.dw_dlat_radps[s][k] = Rt * (quat(raw[k]).conjugate() * dearth_dlat_enu);
      if (s < out.sensors && !raw[k].g[s].allFinite()) out.usable[k] = 0;
    }
  }
  out.rows_missing_gyro = static_cast<std::size_t>(std::count(out.usable.begin(), out.usable.end(), 0));
}

Replay build(std::vector<Raw> raw, const log::Metadata& meta, std::uint32_t fields, const ReplayOptions& opt,
             const std::string& where) {
  opt.validate();
  Replay out;
  out.log_path = where;
  if (raw.size() < 10) {
    throw std::runtime_error(fmt::format("{}: only {} samples; compare needs at least 10", where, raw.size()));
  }
  read_header(meta, fields, out);
  single_sensor(raw, out);
  set_rate(raw, opt, out);
  double lat = meta.latitude_deg();
  if (!std::isfinite(lat)) {
    lat = opt.default_latitude_deg;
    out.notes.push_back(fmt::format("the log states no latitude_deg; {:.4f} deg is assumed for the Earth rate", lat));
  }
  out.latitude_deg = lat;
  check_attitude(raw, opt, out);
  const Eigen::Vector3d earth_enu = geo::earth_rate_enu_radps(lat);
  const Eigen::Vector3d dearth_dlat_enu = geo::earth_rate_enu_dlat_radps_per_rad(lat);
  body_rate(raw, earth_enu, opt, out);
  specific_force(raw, out);
  flip_history(raw, platform_motion(raw, opt, out), out);
  sensor_truth(raw, dearth_dlat_enu, out);
  return out;
}

}  // namespace

Eigen::Vector3d Replay::dw_radps2(int s, std::size_t k) const {
  const std::size_t n = size();
  const std::size_t a = k == 0 ? 0 : k - 1, b = k + 1 < n ? k + 1 : n - 1;
  Eigen::Vector3d d = (w_radps[s][b] - w_radps[s][a]) / (t_s[b] - t_s[a]);
  if (!d.allFinite()) d.setZero();
  return d;
}

void ReplayOptions::validate() const {
  auto positive = [](double v, const char* name) {
    if (!(v > 0) || !std::isfinite(v)) {
      throw std::invalid_argument(fmt::format("ReplayOptions.{} must be > 0, got {}", name, v));
    }
  };
  if (!std::isnan(resample_hz)) positive(resample_hz, "resample_hz");
  positive(flip_rate_threshold_dps, "flip_rate_threshold_dps");
  positive(static_rate_limit_dps, "static_rate_limit_dps");
  positive(replay_error_limit_dps, "replay_error_limit_dps");
  positive(kink_ratio, "kink_ratio");
  if (!(rough_guard_s >= 0)) throw std::invalid_argument("ReplayOptions.rough_guard_s must be >= 0");
  if (!(flip_guard_s >= 0)) throw std::invalid_argument("ReplayOptions.flip_guard_s must be >= 0");
  if (!(std::abs(default_latitude_deg) <= 90)) {
    throw std::invalid_argument("ReplayOptions.default_latitude_deg must be within [-90, 90] deg");
  }
}

Replay replay_samples(const std::vector<Sample>& samples, const log::Metadata& meta,
                      std::uint32_t fields, const ReplayOptions& opt, const std::string& where) {
  std::vector<Raw> raw;
  raw.reserve(samples.size());
  for (const auto& s : samples) raw.push_back(to_raw(s));
  return build(std::move(raw), meta, fields, opt, where);
}

Replay replay_log(const std::filesystem::path& path, const ReplayOptions& opt) {
  log::ReaderOptions ro;
  ro.accept_single_sensor = true;
  ro.fields = kFieldAccel | kFieldTemp | kFieldRefQ | kFieldRefP;  // the truth columns are never read here
  log::LogReader reader(path, ro);
  std::vector<Raw> raw;
  Sample s;
  while (reader.next(s)) raw.push_back(to_raw(s));
  Replay r = build(std::move(raw), reader.metadata(), reader.fields(), opt, path.string());
  if (!reader.metadata().complete()) {
    r.notes.push_back("the log says 'complete: false' (the recording did not finish)");
  }
  return r;
}

}  // namespace driftless::diagnose
