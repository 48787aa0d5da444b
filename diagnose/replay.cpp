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

// the columns a replay needs, one vector per column (a 1 h log at 100 Hz is 360k rows): the
// measured ones (t, gyro, platform angles, temperature, accel) are moved into the Replay when it
// is built, and ref_p / accel are kept only when the log has them
struct Raw {
  explicit Raw(std::uint32_t fields) : with_p((fields & kFieldRefP) != 0), with_a((fields & kFieldAccel) != 0) {}
  std::size_t size() const { return n; }
  void push(const Sample& s) {
    t.push_back(s.t_s);
    g[0].push_back(s.gyro1_dps), g[1].push_back(s.gyro2_dps);
    plat[0].push_back(s.plat1_deg), plat[1].push_back(s.plat2_deg);
    temp[0].push_back(s.temp1_c), temp[1].push_back(s.temp2_c);
    q.push_back(s.ref_q_wxyz);
    if (with_p) p.push_back(s.ref_p_enu_m);
    if (with_a) a[0].push_back(s.accel1_mps2), a[1].push_back(s.accel2_mps2);
    ++n;
  }
  // room for `rows` rows, so the columns do not grow by doubling (each doubling copies the column
  // and leaves the old one as freed heap: 38 MB of an hour's replay were such holes)
  void reserve(std::size_t rows) {
    t.reserve(rows);
    for (int s = 0; s < 2; ++s) {
      g[s].reserve(rows), plat[s].reserve(rows), temp[s].reserve(rows);
      if (with_a) a[s].reserve(rows);
    }
    q.reserve(rows);
    if (with_p) p.reserve(rows);
  }
  // gives back what the vectors' growth reserved beyond 1 %, one column at a time
  void shrink() {
    auto fit = [](auto& v) {
      if (v.capacity() > v.size() + v.size() / 100 + 64) v.shrink_to_fit();
    };
    for (auto* v : {&t, &plat[0], &plat[1], &temp[0], &temp[1]}) fit(*v);
    for (auto* v : {&g[0], &g[1], &a[0], &a[1], &p}) fit(*v);
    fit(q);
  }
  std::size_t n = 0;
  bool with_p = false, with_a = false;
  std::vector<double> t;
  std::array<std::vector<Eigen::Vector3d>, 2> g, a;
  std::array<std::vector<double>, 2> plat, temp;
  std::vector<Eigen::Vector4d> q;
  std::vector<Eigen::Vector3d> p;
};

double lerp(double a, double b, double u) { return a + (b - a) * u; }

// linear interpolation of every column onto a uniform grid at rate_hz (quaternions: nlerp)
Raw resample(Raw&& in, double rate_hz) {
  if (in.size() < 2) return std::move(in);
  Raw out(0);
  out.with_p = in.with_p, out.with_a = in.with_a;
  const double t0 = in.t.front(), t1 = in.t.back();
  const auto n = static_cast<std::size_t>(std::floor((t1 - t0) * rate_hz + 1e-9)) + 1;
  std::size_t j = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const double t = t0 + static_cast<double>(k) / rate_hz;
    while (j + 2 < in.size() && in.t[j + 1] <= t) ++j;
    const std::size_t a = j, b = j + 1;
    const double u = std::clamp((t - in.t[a]) / (in.t[b] - in.t[a]), 0.0, 1.0);
    out.t.push_back(t);
    for (int s = 0; s < 2; ++s) {
      out.g[s].push_back(in.g[s][a] + (in.g[s][b] - in.g[s][a]) * u);
      if (in.with_a) out.a[s].push_back(in.a[s][a] + (in.a[s][b] - in.a[s][a]) * u);
      out.plat[s].push_back(lerp(in.plat[s][a], in.plat[s][b], u));
      out.temp[s].push_back(lerp(in.temp[s][a], in.temp[s][b], u));
    }
    Eigen::Vector4d qb = in.q[b];
    if (in.q[a].dot(qb) < 0) qb = -qb;
    Eigen::Vector4d q = (in.q[a] + (qb - in.q[a]) * u);
    if (q.allFinite()) q.normalize();
    out.q.push_back(q);
    if (in.with_p) out.p.push_back(in.p[a] + (in.p[b] - in.p[a]) * u);
    ++out.n;
  }
  return out;
}

// median sample interval, s
double median_dt(const Raw& raw) {
  std::vector<double> dt;
  dt.reserve(raw.size());
  for (std::size_t k = 1; k < raw.size(); ++k) dt.push_back(raw.t[k] - raw.t[k - 1]);
  if (dt.empty()) return kNaN;
  auto mid = dt.begin() + static_cast<std::ptrdiff_t>(dt.size() / 2);
  std::nth_element(dt.begin(), mid, dt.end());
  return *mid;
}

// largest swing of a sensor's output inside rest intervals of both platforms, deg/s
double largest_rest_swing_dps(const Raw& raw, double fs) {
  // a running median over 1 s suppresses noise; the swing is the spread of that median
  // between consecutive platform flips (a static box only sees bias + Earth rate there)
  const auto w = static_cast<std::size_t>(std::max(1.0, std::round(fs)));
  double worst = 0.0;
  std::size_t seg_start = 0;
  auto same_rest = [&](std::size_t a, std::size_t b) {
    for (int s = 0; s < 2; ++s) {
      if (!std::isfinite(raw.plat[s][a]) || !std::isfinite(raw.plat[s][b])) return false;
      if (std::abs(raw.plat[s][a] - raw.plat[s][b]) > 0.5) return false;
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
            if (std::isfinite(raw.g[s][i][ax])) buf.push_back(raw.g[s][i][ax]);
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
// With M = 8 its response is flat to 1e-9 at 0.1 fs, 1e-4 at 0.2 fs, 1 % at 0.3 fs; with M = 4,
// 1e-6 at 0.1 fs
std::vector<double> central_differentiator(int M) {
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
void single_sensor(Raw& raw, Replay& out) {
  if (out.sensors != 1) return;
  if (!out.has_ref_q) {
    throw std::runtime_error(fmt::format(
        "{}: a single-sensor log ('sensors: 1') without ref_q (ref_qw, ref_qx, ref_qy, ref_qz); compare and diagnose "
        "need the body's reference attitude to predict one IMU (join motion capture or a trajectory with "
        "'driftless convert --ref'; docs/log-format.md)", out.log_path));
  }
  std::fill(raw.plat[1].begin(), raw.plat[1].end(), 0.0);
  out.notes.push_back("a single-sensor log: one IMU against the reference attitude (ref_q); the sensor-2 channels, "
                      "platform flips and end stops take no part");
}

// the sample rate: metadata, else the median interval; resampled when asked
void set_rate(Raw& raw, const ReplayOptions& opt, Replay& out) {
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
    raw = resample(std::move(raw), opt.resample_hz);
    out.resampled = true;
    out.notes.push_back(fmt::format("the log ({:.3f} Hz) was resampled to {:.3f} Hz by linear interpolation", fs, opt.resample_hz));
    fs = opt.resample_hz;
  }
  out.sample_rate_hz = fs;
}

// attitude: ref_q, or (static logs only) identity with the Earth rate as the only rate
void check_attitude(Raw& raw, const ReplayOptions& opt, Replay& out) {
  if (!out.has_ref_q) {
    const double swing = largest_rest_swing_dps(raw, out.sample_rate_hz);
    if (swing > opt.static_rate_limit_dps) {
      throw std::runtime_error(fmt::format(
          "{}: the log has no reference motion (ref_qw, ref_qx, ref_qy, ref_qz) but the box moves (the gyro output swings "
          "by {:.2f} deg/s while both platforms rest); compare needs ref_q (and ref_p for accelerations) to replay a "
          "moving box (docs/log-format.md)", out.log_path, swing));
    }
    std::fill(raw.q.begin(), raw.q.end(), Eigen::Vector4d(1, 0, 0, 0));
    out.notes.push_back("the log has no ref_q: the box is assumed static and level with body axes = ENU (identity "
                        "attitude), so the body rate is the Earth rate only");
  }
  for (std::size_t k = 0; k < raw.size(); ++k) {
    Eigen::Vector4d& q = raw.q[k];
    if (!q.allFinite() || q.norm() < 0.5) {
      throw std::runtime_error(fmt::format("{}: ref_q at t = {:.6f} s is empty or not a unit quaternion", out.log_path, raw.t[k]));
    }
    q.normalize();
  }
}

Eigen::Quaterniond quat(const Eigen::Vector4d& q) { return Eigen::Quaterniond(q[0], q[1], q[2], q[3]); }

// a kink of the rate (a motion profile starting or ending an acceleration) is not band limited:
// no stencil rebuilds the rate near it. It shows as an isolated spike of the second difference
// of the interval means; continuous vibration raises them everywhere and is not a kink (the FIR
// rebuilds it)
// (d2: per sample the largest axis of the second difference of the interval mean rates, rad/s)
void mark_kinks(const std::vector<double>& d2, std::size_t fir_half, const ReplayOptions& opt, Replay& out) {
  const std::size_t n = out.size();
  const double limit = opt.replay_error_limit_dps * kRadPerDeg;
  std::vector<double> csum(n + 1, 0.0);
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
std::vector<Eigen::Vector3d> body_rate(Raw& raw, const Eigen::Vector3d& earth_enu, const ReplayOptions& opt, Replay& out) {
  const std::size_t n = raw.size();
  out.t_s = std::move(raw.t);
  // one hemisphere: q and -q are one rotation (in place: every later use rotates with q, which
  // gives the same bits for -q, or takes the shortest rotation vector)
  std::vector<Eigen::Vector4d>& q = raw.q;
  for (std::size_t k = 1; k < n; ++k)
    if (q[k].dot(q[k - 1]) < 0) q[k] = -q[k];
  const std::vector<double> d = central_differentiator(8);
  const auto M = d.size();
  std::vector<Eigen::Vector3d> w_body(n);
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
    w_body[k] = w_eb + qk.conjugate() * earth_enu;
  }
  // kinks from the second differences of the interval mean rates (three kept at a time)
  std::vector<double> d2(n, 0.0);
  auto mean_rate = [&](std::size_t k) {
    return Eigen::Vector3d(geo::rotvec_rad(quat(q[k]).conjugate() * quat(q[k + 1])) / (out.t_s[k + 1] - out.t_s[k]));
  };
  if (n >= 3) {
    Eigen::Vector3d m0 = mean_rate(0), m1 = mean_rate(1);
    for (std::size_t k = 1; k + 2 < n; ++k) {
      const Eigen::Vector3d m2 = mean_rate(k + 1);
      d2[k] = (m2 - 2.0 * m1 + m0).cwiseAbs().maxCoeff();
      m0 = m1, m1 = m2;
    }
  }
  mark_kinks(d2, M, opt, out);
  // the first and last M samples have no full differentiator stencil: left out like a kink
  for (std::size_t k = 0; k < std::min(n, M); ++k) out.rough[k] = out.rough[n - 1 - k] = 1;
  return w_body;
}

// specific force in body axes: second differences of ref_p, else gravity only (double here: the
// sensors' series are rotated from it; the Replay keeps a float copy)
std::vector<Eigen::Vector3d> specific_force(Raw& raw, Replay& out) {
  const std::size_t n = raw.size();
  bool p_ok = out.has_ref_p;
  if (p_ok) {
    for (const auto& p : raw.p) p_ok = p_ok && p.allFinite();
    if (!p_ok) out.notes.push_back("ref_p has empty values; accelerations set to zero");
  }
  const Eigen::Vector3d g_enu(0, 0, kStandardGravityMps2);  // f = a - g, g = (0,0,-9.81)
  std::vector<Eigen::Vector3d> f_body(n);
  out.f_body_mps2.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    Eigen::Vector3d a_enu = Eigen::Vector3d::Zero();
    if (p_ok && k > 0 && k + 1 < n) {
      const double h1 = out.t_s[k] - out.t_s[k - 1], h2 = out.t_s[k + 1] - out.t_s[k];
      a_enu = 2.0 * ((raw.p[k + 1] - raw.p[k]) / h2 - (raw.p[k] - raw.p[k - 1]) / h1) / (h1 + h2);
    }
    f_body[k] = quat(raw.q[k]).conjugate() * (a_enu + g_enu);
    out.f_body_mps2[k] = f_body[k].cast<float>();
  }
  raw.p = std::vector<Eigen::Vector3d>();  // ref_p is used up (not "= {}": that keeps the memory)
  if (!out.has_accel && !p_ok) {
    out.notes.push_back("no ref_p and no accel columns: the specific force is gravity alone (vehicle accelerations unknown)");
  }
  if (out.has_accel) out.notes.push_back("the specific force on each sensor is taken from the log's accel columns");
  return f_body;
}

// platforms: angle as logged, rate by central differences (NaN unknown); unknown angle = moving
struct PlatformMotion {
  std::array<std::vector<std::uint8_t>, 2> moving;
  std::array<std::vector<double>, 2> rate_dps;
};

PlatformMotion platform_motion(Raw& raw, const ReplayOptions& opt, Replay& out) {
  const std::size_t n = raw.size();
  PlatformMotion pm;
  for (int s = 0; s < 2; ++s) {
    const std::vector<double>& plat = raw.plat[s];
    std::vector<double>& rate = pm.rate_dps[s];
    rate.resize(n);
    if (out.has_temp) {
      out.temp_c[s].assign(raw.temp[s].begin(), raw.temp[s].end());
    } else {
      out.temp_c[s].assign(n, std::numeric_limits<float>::quiet_NaN());
    }
    raw.temp[s] = std::vector<double>();
    pm.moving[s].assign(n, 0);
    for (std::size_t k = 0; k < n; ++k) {
      const std::size_t a = k == 0 ? 0 : k - 1, b = k + 1 < n ? k + 1 : n - 1;
      rate[k] = std::isfinite(plat[k]) ? (plat[b] - plat[a]) / (out.t_s[b] - out.t_s[a]) : kNaN;
      pm.moving[s][k] = !std::isfinite(rate[k]) || std::abs(rate[k]) > opt.flip_rate_threshold_dps;
    }
  }
  // flips: a platform turning or unknown; guard a few samples around it, and at least the
  // angular-acceleration stencil's half width: a sample whose stencil reaches into a flip takes
  // the flip's rates into its regressors (at 10 Hz, 0.05 s is one sample and the stencil four)
  out.flipping.assign(n, 0);
  const auto guard = std::max(static_cast<std::size_t>(std::ceil(opt.flip_guard_s * out.sample_rate_hz)),
                              Replay::kAngularAccelHalfWidth);
  for (std::size_t k = 0; k < n; ++k) {
    if (!(pm.moving[0][k] || pm.moving[1][k])) continue;
    const std::size_t a = k >= guard ? k - guard : 0, b = std::min(n - 1, k + guard);
    for (std::size_t i = a; i <= b; ++i) out.flipping[i] = 1;
  }
  return pm;
}

// per platform: time since it last stopped, the direction it went, the side it rests on
void flip_history(const Raw& raw, const std::array<std::vector<std::uint8_t>, 2>& moving, Replay& out) {
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
        if (!was_moving) start_angle = k > 0 ? raw.plat[s][k - 1] : kNaN;  // the last known angle before the move
        was_moving = true;
        continue;
      }
      if (was_moving) {
        stop_t = out.t_s[k];
        const double end_angle = raw.plat[s][k];
        dir = (std::isfinite(start_angle) && std::isfinite(end_angle)) ? (end_angle > start_angle ? 1 : -1) : 0;
        was_moving = false;
      }
      if (std::isfinite(stop_t)) {
        out.since_flip_s[s][k] = static_cast<float>(out.t_s[k] - stop_t);
        out.last_flip_dir[s][k] = static_cast<std::int8_t>(dir);
      }
      const double ang = raw.plat[s][k];
      if (std::isfinite(ang) && std::abs(ang) > 1.0) out.rest_side[s][k] = ang > 0 ? 1 : -1;
    }
  }
}

// each sensor's ideal output (docs/log-format.md): y_i = R_i^T w_body + thetadot_i a_i
void sensor_truth(Raw& raw, const std::vector<Eigen::Vector3d>& w_body, const std::vector<Eigen::Vector3d>& f_body,
                  const PlatformMotion& pm, const Eigen::Vector3d& earth_enu, const Eigen::Vector3d& dearth_dlat_enu,
                  Replay& out) {
  const std::size_t n = raw.size();
  out.usable.assign(n, 1);
  // the Earth rate's parts in box axes (the sensors' follow with their platform angles)
  out.dw_dlat_box_radps.resize(n);
  if (out.latitude_assumed) out.earth_box_radps.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    const Eigen::Quaterniond qc = quat(raw.q[k]).conjugate();
    out.dw_dlat_box_radps[k] = (qc * dearth_dlat_enu).cast<float>();
    if (out.latitude_assumed) out.earth_box_radps[k] = (qc * earth_enu).cast<float>();
  }
  const Eigen::Vector3f nan3 = Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN());
  for (int s = 0; s < 2; ++s) {
    out.w_radps[s].resize(n);
    // the log's accel columns are the specific force where they are finite
    std::vector<Eigen::Vector3f>& f = out.f_mps2[s];
    f.resize(n);
    const Eigen::Vector3d& axis = out.hinge_axis[s];
    for (std::size_t k = 0; k < n; ++k) {
      const double ang = raw.plat[s][k];
      if (!std::isfinite(ang)) {
        out.w_radps[s][k].setConstant(kNaN);
        f[k] = nan3;
        out.usable[k] = 0;
        continue;
      }
      const Eigen::Matrix3d Rt = geo::rot_about_axis_deg(axis, ang).transpose();
      const double rate = pm.rate_dps[s][k];
      out.w_radps[s][k] = Rt * w_body[k] + (std::isfinite(rate) ? rate : 0.0) * kRadPerDeg * axis;
      const bool logged = out.has_accel && raw.a[s][k].allFinite();
      f[k] = (logged ? raw.a[s][k] : Eigen::Vector3d(Rt * f_body[k])).cast<float>();
      if (s < out.sensors && !raw.g[s][k].allFinite()) out.usable[k] = 0;
    }
    raw.a[s] = std::vector<Eigen::Vector3d>();
    out.gyro_dps[s] = std::move(raw.g[s]);
    out.plat_deg[s].assign(raw.plat[s].begin(), raw.plat[s].end());
    raw.plat[s] = std::vector<double>();
  }
  out.rows_missing_gyro = static_cast<std::size_t>(std::count(out.usable.begin(), out.usable.end(), 0));
}

Replay build(Raw raw, const log::Metadata& meta, std::uint32_t fields, const ReplayOptions& opt,
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
    out.latitude_assumed = true;
  }
  out.latitude_deg = lat;
  check_attitude(raw, opt, out);
  const Eigen::Vector3d earth_enu = geo::earth_rate_enu_radps(lat);
  const Eigen::Vector3d dearth_dlat_enu = geo::earth_rate_enu_dlat_radps_per_rad(lat);
  const std::vector<Eigen::Vector3d> w_body = body_rate(raw, earth_enu, opt, out);
  const std::vector<Eigen::Vector3d> f_body = specific_force(raw, out);
  const PlatformMotion pm = platform_motion(raw, opt, out);
  flip_history(raw, pm.moving, out);
  sensor_truth(raw, w_body, f_body, pm, earth_enu, dearth_dlat_enu, out);
  out.w_body_radps.resize(w_body.size());
  for (std::size_t k = 0; k < w_body.size(); ++k) out.w_body_radps[k] = w_body[k].cast<float>();
  return out;
}

// the rows a log's metadata announce (duration_s x sample_rate_hz + 1), at most what the file's
// size can hold (a row has at least 40 characters); 0 when it does not say
std::size_t expected_rows(const log::Metadata& meta, const std::filesystem::path& path) {
  const double fs = meta.sample_rate_hz(), dur = meta.get_number("duration_s", kNaN);
  if (!(fs > 0) || !(dur > 0) || !std::isfinite(fs * dur)) return 0;
  std::error_code ec;
  const auto bytes = std::filesystem::file_size(path, ec);
  if (ec) return 0;
  return static_cast<std::size_t>(std::min(fs * dur + 1.0, static_cast<double>(bytes / 40)));
}

}  // namespace

// the angular acceleration by the maximally flat differentiator of 2 x 4 neighbours where they
// exist (central differences near the ends and where a neighbour is not finite). A three-point
// difference has the error h^2/6 w''': times a delay change it reads like the signal chain's
// third-order term, 17x the true one for 4.8 ms at 50 Hz, and on a wobble that projects onto the
// tilt (a g-sensitivity of 0.05 deg/s/g that is not there)
double Replay::dw_axis_radps2(int s, std::size_t k, int j) const {
  constexpr std::size_t M = kAngularAccelHalfWidth;
  static const std::vector<double> d4 = central_differentiator(static_cast<int>(M));
  const std::size_t n = size();
  const auto& w = w_radps[s];
  if (k >= M && k + M < n) {
    const double h = (t_s[k + M] - t_s[k - M]) / static_cast<double>(2 * M);
    double d = 0.0;
    for (std::size_t i = 1; i <= M; ++i) d += d4[i - 1] * (w[k + i][j] - w[k - i][j]);
    d /= h;
    if (std::isfinite(d)) return d;
  }
  const std::size_t a = k == 0 ? 0 : k - 1, b = k + 1 < n ? k + 1 : n - 1;
  const double d = (w[b][j] - w[a][j]) / (t_s[b] - t_s[a]);
  return std::isfinite(d) ? d : 0.0;
}

Eigen::Matrix3d Replay::sensor_from_box(int s, std::size_t k) const {
  const double ang = plat_deg[s][k];
  if (!std::isfinite(ang)) return Eigen::Matrix3d::Constant(kNaN);
  return geo::rot_about_axis_deg(hinge_axis[s], ang).transpose();
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
  Raw raw(fields);
  for (const auto& s : samples) raw.push(s);
  return build(std::move(raw), meta, fields, opt, where);
}

Replay replay_log(const std::filesystem::path& path, const ReplayOptions& opt) {
  log::ReaderOptions ro;
  ro.accept_single_sensor = true;
  ro.fields = kFieldAccel | kFieldTemp | kFieldRefQ | kFieldRefP;  // the truth columns are never read here
  log::LogReader reader(path, ro);
  Raw raw(reader.fields());
  raw.reserve(expected_rows(reader.metadata(), path));
  Sample s;
  while (reader.next(s)) raw.push(s);
  raw.shrink();
  Replay r = build(std::move(raw), reader.metadata(), reader.fields(), opt, path.string());
  if (!reader.metadata().complete()) {
    r.notes.push_back("the log says 'complete: false' (the recording did not finish)");
  }
  // a clipping gyro makes the effects fit the rail: said first, before any effect is believed
  for (const est::ClippedChannel& c : reader.suspected_clipping()) {
    const bool at_rest = c.samples_at_rest >= est::ClipDetector::kMinSamples;
    r.notes.insert(r.notes.begin(),
                   fmt::format("{} repeats its largest value, +-{:g} deg/s, in runs ({} samples, {} with the "
                               "platforms at rest): the sensor clips there{}",
                               log::gyro_column_name(c.channel), c.level_dps, c.samples, c.samples_at_rest,
                               at_rest ? "; effects fitted on that channel (and the residual it shares) are not to "
                                         "be trusted: record with a larger full scale or slower motion"
                                       : ", only while a platform turns (the flips, which the fits leave out)"));
  }
  return r;
}

}  // namespace driftless::diagnose
