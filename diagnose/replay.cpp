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

// taps c_0..c_{M-1} of the symmetric FIR w_k = sum_j c_j (m_{k+j} + m_{k-1-j}) over interval
// mean rates m: least squares on the response 2 sum_j c_j cos(2 pi f h (j + 1/2)) sinc(f h) = 1
// for f h in [0, 0.42], with the DC gain held at exactly 1 (a linear rate is rebuilt exactly)
std::vector<double> interval_mean_fir() {
  constexpr int M = 4;
  constexpr int F = 120;
  Eigen::MatrixXd A(F + 1, M);
  Eigen::VectorXd b = Eigen::VectorXd::Ones(F + 1);
  for (int i = 0; i <= F; ++i) {
    const double x = 0.42 * i / F;  // f h
    const double sinc = x == 0.0 ? 1.0 : std::sin(kPi * x) / (kPi * x);
    const double wgt = i == 0 ? 1e4 : 1.0;
    for (int j = 0; j < M; ++j) A(i, j) = wgt * 2.0 * std::cos(2.0 * kPi * x * (j + 0.5)) * sinc;
    b[i] = wgt;
  }
  const Eigen::VectorXd c = A.colPivHouseholderQr().solve(b);
  return std::vector<double>(c.data(), c.data() + M);
}

Replay build(std::vector<Raw> raw, const log::Metadata& meta, std::uint32_t fields,
             const ReplayOptions& opt, const std::string& where) {
  opt.validate();
  Replay out;
  out.meta = meta;
  out.log_path = where;
  if (raw.size() < 10) {
    throw std::runtime_error(fmt::format("{}: only {} samples; compare needs at least 10", where,
                                         raw.size()));
  }
  out.has_ref_q = (fields & kFieldRefQ) != 0;
  out.has_ref_p = (fields & kFieldRefP) != 0;
  out.has_accel = (fields & kFieldAccel) != 0;
  out.has_temp = (fields & kFieldTemp) != 0;
  out.encoder_readback = meta.get("platform_readback").value_or("") == "encoder";
  out.hinge_axis[0] = meta.hinge1_axis().normalized();
  out.hinge_axis[1] = meta.hinge2_axis().normalized();

  // sample rate: metadata, else the median interval; compare with the model's
  const double dt_med = median_dt(raw);
  double fs = meta.sample_rate_hz();
  if (!std::isfinite(fs) || fs <= 0) {
    fs = 1.0 / dt_med;
    out.notes.push_back(fmt::format("the log states no sample_rate_hz; {:.3f} Hz taken from the "
                                    "median sample interval",
                                    fs));
  } else if (std::abs(1.0 / dt_med - fs) > 0.01 * fs) {
    out.notes.push_back(fmt::format("the log says sample_rate_hz {:.3f} but its median interval "
                                    "gives {:.3f} Hz; the interval is used",
                                    fs, 1.0 / dt_med));
    fs = 1.0 / dt_med;
  }
  out.log_rate_hz = fs;
  if (std::isfinite(opt.model_sample_rate_hz) &&
      std::abs(fs - opt.model_sample_rate_hz) > 0.01 * opt.model_sample_rate_hz) {
    if (!opt.resample) {
      throw std::runtime_error(fmt::format(
          "{}: the log is sampled at {:.3f} Hz but the model at {:.3f} Hz; refused (the sensor "
          "model's filters depend on the rate). Pass --resample to resample the log to the "
          "model's rate, or set sample_rate_hz in the model file",
          where, fs, opt.model_sample_rate_hz));
    }
    raw = resample(raw, opt.model_sample_rate_hz);
    out.resampled = true;
    out.notes.push_back(fmt::format("the log ({:.3f} Hz) was resampled to the model's {:.3f} Hz "
                                    "by linear interpolation",
                                    fs, opt.model_sample_rate_hz));
    fs = opt.model_sample_rate_hz;
  }
  out.sample_rate_hz = fs;

  double lat = meta.latitude_deg();
  if (!std::isfinite(lat)) {
    lat = opt.default_latitude_deg;
    out.notes.push_back(fmt::format("the log states no latitude_deg; {:.4f} deg is assumed for "
                                    "the Earth rate",
                                    lat));
  }
  out.latitude_deg = lat;

  // attitude: ref_q, or (static logs only) identity with the Earth rate as the only rate
  const std::size_t n = raw.size();
  if (!out.has_ref_q) {
    const double swing = largest_rest_swing_dps(raw, fs);
    if (swing > opt.static_rate_limit_dps) {
      throw std::runtime_error(fmt::format(
          "{}: the log has no reference motion (ref_qw, ref_qx, ref_qy, ref_qz) but the box moves "
          "(the gyro output swings by {:.2f} deg/s while both platforms rest); compare needs "
          "ref_q (and ref_p for accelerations) to replay a moving box (docs/log-format.md)",
          where, swing));
    }
    for (auto& r : raw) r.q = Eigen::Vector4d(1, 0, 0, 0);
    out.notes.push_back("the log has no ref_q: the box is assumed static and level with body "
                        "axes = ENU (identity attitude), so the body rate is the Earth rate only");
  }
  for (std::size_t k = 0; k < n; ++k) {
    if (!raw[k].q.allFinite() || raw[k].q.norm() < 0.5) {
      throw std::runtime_error(fmt::format("{}: ref_q at t = {:.6f} s is empty or not a unit "
                                           "quaternion",
                                           where, raw[k].t));
    }
    raw[k].q.normalize();
  }

  const Eigen::Vector3d earth_enu = geo::earth_rate_enu_radps(lat);
  const Eigen::Vector3d dearth_dlat_enu = geo::earth_rate_enu_dlat_radps_per_rad(lat);
  const Eigen::Vector3d g_enu(0, 0, kStandardGravityMps2);  // f = a - g, g = (0,0,-9.81)

  auto quat = [&](std::size_t k) {
    return Eigen::Quaterniond(raw[k].q[0], raw[k].q[1], raw[k].q[2], raw[k].q[3]);
  };

  out.t_s.resize(n);
  out.w_body_radps.resize(n);
  out.f_body_mps2.resize(n);
  std::vector<Eigen::Matrix3d> R_enu_from_body(n);
  for (std::size_t k = 0; k < n; ++k) {
    out.t_s[k] = raw[k].t;
    R_enu_from_body[k] = quat(k).toRotationMatrix();
  }
  // body rate relative to ENU from the attitude: each interval's rotation (right increments give
  // body axes) over its length is the mean rate over that interval, i.e. the rate seen through a
  // one-sample box filter half a sample late. A symmetric FIR over those interval means undoes
  // the box filter up to 0.42 fs (band-limited reconstruction: a vehicle's 30 Hz vibration is
  // rebuilt, where central differences lose half of it); it is exact for a rate linear in time.
  // The Earth rate is added in body axes; the transport rate (v/R) is neglected.
  out.rough.assign(n, 0);
  {
    std::vector<Eigen::Vector3d> mean_rate(n - 1);
    for (std::size_t k = 0; k + 1 < n; ++k) {
      const Eigen::Quaterniond dq = quat(k).conjugate() * quat(k + 1);
      mean_rate[k] = geo::rotvec_rad(dq) / (out.t_s[k + 1] - out.t_s[k]);
    }
    const std::vector<double> c = interval_mean_fir();
    const auto M = c.size();
    for (std::size_t k = 0; k < n; ++k) {
      Eigen::Vector3d w_eb;
      if (k >= M && k + M < n) {
        w_eb.setZero();
        for (std::size_t j = 0; j < M; ++j) w_eb += c[j] * (mean_rate[k + j] + mean_rate[k - 1 - j]);
      } else if (k > 0 && k + 1 < n) {
        w_eb = 0.5 * (mean_rate[k - 1] + mean_rate[k]);
      } else {
        w_eb = mean_rate[k == 0 ? 0 : n - 2];
      }
      out.w_body_radps[k] = w_eb + R_enu_from_body[k].transpose() * earth_enu;
    }
    // a kink of the rate (a motion profile starting or ending an acceleration) is not band
    // limited: no stencil rebuilds the rate near it. It shows as an isolated spike of the second
    // difference of the interval means; continuous vibration raises them everywhere and is not a
    // kink (the FIR rebuilds it).
    const double limit = opt.replay_error_limit_dps * kRadPerDeg;
    std::vector<double> d2(n, 0.0), csum(n + 1, 0.0);
    for (std::size_t k = 1; k + 1 < mean_rate.size(); ++k) {
      d2[k] = (mean_rate[k + 1] - 2.0 * mean_rate[k] + mean_rate[k - 1]).cwiseAbs().maxCoeff();
    }
    for (std::size_t k = 0; k < n; ++k) csum[k + 1] = csum[k] + d2[k];
    const auto half = static_cast<std::size_t>(std::max(5.0, std::round(0.5 * fs)));
    const auto spread = static_cast<std::size_t>(std::ceil(opt.rough_guard_s * fs)) + M;
    for (std::size_t k = 1; k + 1 < n; ++k) {
      if (d2[k] <= limit) continue;
      const std::size_t lo = k >= half ? k - half : 0, hi = std::min(n, k + half + 1);
      const double local = (csum[hi] - csum[lo] - d2[k]) / static_cast<double>(hi - lo - 1);
      if (d2[k] <= opt.kink_ratio * local) continue;
      const std::size_t a = k >= spread ? k - spread : 0, b = std::min(n - 1, k + spread + 1);
      for (std::size_t i = a; i <= b; ++i) out.rough[i] = 1;
    }
    const auto rough_count = static_cast<std::size_t>(std::count(out.rough.begin(), out.rough.end(), 1));
    if (rough_count > 0) {
      out.notes.push_back(fmt::format(
          "{} samples ({:.1f} %) near kinks of the reference rate (a motion profile's acceleration steps), where "
          "the rate cannot be rebuilt from ref_q to within {:.3g} deg/s, are left out of the fits",
          rough_count, 100.0 * static_cast<double>(rough_count) / static_cast<double>(n), opt.replay_error_limit_dps));
    }
  }
  // specific force in body axes: second differences of ref_p, else gravity only
  bool p_ok = out.has_ref_p;
  if (p_ok) {
    for (const auto& r : raw) p_ok = p_ok && r.p.allFinite();
    if (!p_ok) out.notes.push_back("ref_p has empty values; accelerations set to zero");
  }
  for (std::size_t k = 0; k < n; ++k) {
    Eigen::Vector3d a_enu = Eigen::Vector3d::Zero();
    if (p_ok && k > 0 && k + 1 < n) {
      const double h1 = out.t_s[k] - out.t_s[k - 1], h2 = out.t_s[k + 1] - out.t_s[k];
      a_enu = 2.0 * ((raw[k + 1].p - raw[k].p) / h2 - (raw[k].p - raw[k - 1].p) / h1) / (h1 + h2);
    }
    out.f_body_mps2[k] = R_enu_from_body[k].transpose() * (a_enu + g_enu);
  }
  if (!out.has_accel && !p_ok) {
    out.notes.push_back("no ref_p and no accel columns: the specific force is gravity alone "
                        "(vehicle accelerations unknown)");
  }
  if (out.has_accel) {
    out.notes.push_back("the specific force on each sensor is taken from the log's accel "
                        "columns");
  }

  // platforms: angle as logged, rate by central differences; unknown angle = flipping
  for (int s = 0; s < 2; ++s) {
    out.plat_deg[s].resize(n);
    out.plat_rate_dps[s].resize(n);
    out.temp_c[s].resize(n);
    for (std::size_t k = 0; k < n; ++k) {
      out.plat_deg[s][k] = raw[k].plat[s];
      out.temp_c[s][k] = out.has_temp ? raw[k].temp[s] : kNaN;
      const std::size_t a = k == 0 ? 0 : k - 1;
      const std::size_t b = k + 1 < n ? k + 1 : n - 1;
      out.plat_rate_dps[s][k] = (raw[b].plat[s] - raw[a].plat[s]) / (out.t_s[b] - out.t_s[a]);
      if (!std::isfinite(raw[k].plat[s])) out.plat_rate_dps[s][k] = kNaN;
    }
  }

  // flips: a platform turning or unknown; guard a few samples around it
  out.flipping.assign(n, 0);
  std::vector<std::uint8_t> moving(n, 0);
  std::array<std::vector<std::uint8_t>, 2> mov_s;
  for (int s = 0; s < 2; ++s) {
    mov_s[s].assign(n, 0);
    for (std::size_t k = 0; k < n; ++k) {
      const double r = out.plat_rate_dps[s][k];
      mov_s[s][k] = !std::isfinite(r) || std::abs(r) > opt.flip_rate_threshold_dps;
    }
  }
  const auto guard = static_cast<std::size_t>(std::ceil(opt.flip_guard_s * fs));
  for (std::size_t k = 0; k < n; ++k) {
    if (!(mov_s[0][k] || mov_s[1][k])) continue;
    const std::size_t a = k >= guard ? k - guard : 0;
    const std::size_t b = std::min(n - 1, k + guard);
    for (std::size_t i = a; i <= b; ++i) out.flipping[i] = 1;
  }
  // per platform: time since it last stopped, the direction it went, the side it rests on
  for (int s = 0; s < 2; ++s) {
    out.since_flip_s[s].assign(n, std::numeric_limits<float>::infinity());
    out.last_flip_dir[s].assign(n, 0);
    out.rest_side[s].assign(n, 0);
    double stop_t = kInf;
    int dir = 0;
    double start_angle = kNaN;
    bool was_moving = false;
    for (std::size_t k = 0; k < n; ++k) {
      if (mov_s[s][k]) {
        if (!was_moving) {
          // the last known angle before the move
          start_angle = k > 0 ? raw[k - 1].plat[s] : kNaN;
        }
        was_moving = true;
        continue;
      }
      if (was_moving) {
        stop_t = out.t_s[k];
        const double end_angle = raw[k].plat[s];
        dir = (std::isfinite(start_angle) && std::isfinite(end_angle))
                  ? (end_angle > start_angle ? 1 : -1)
                  : 0;
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

  // each sensor's ideal output (docs/log-format.md): y_i = R_i^T w_body + thetadot_i a_i
  out.usable.assign(n, 1);
  for (int s = 0; s < 2; ++s) {
    out.gyro_dps[s].resize(n);
    out.w_radps[s].resize(n);
    out.f_mps2[s].resize(n);
    out.dw_radps2[s].resize(n);
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
      const Eigen::Matrix3d R = geo::rot_about_axis_deg(axis, ang);
      const double rate = out.plat_rate_dps[s][k];
      out.w_radps[s][k] =
          R.transpose() * out.w_body_radps[k] + (std::isfinite(rate) ? rate : 0.0) * kRadPerDeg * axis;
      out.f_mps2[s][k] = out.has_accel && raw[k].a[s].allFinite()
                             ? raw[k].a[s]
                             : Eigen::Vector3d(R.transpose() * out.f_body_mps2[k]);
      out.dw_dlat_radps[s][k] = R.transpose() * R_enu_from_body[k].transpose() * dearth_dlat_enu;
      if (!raw[k].g[s].allFinite()) out.usable[k] = 0;
    }
    for (std::size_t k = 0; k < n; ++k) {
      const std::size_t a = k == 0 ? 0 : k - 1;
      const std::size_t b = k + 1 < n ? k + 1 : n - 1;
      out.dw_radps2[s][k] =
          (out.w_radps[s][b] - out.w_radps[s][a]) / (out.t_s[b] - out.t_s[a]);
      if (!out.dw_radps2[s][k].allFinite()) out.dw_radps2[s][k].setZero();
    }
  }
  for (std::size_t k = 0; k < n; ++k) {
    if (!out.usable[k]) ++out.rows_missing_gyro;
  }
  return out;
}

}  // namespace

void ReplayOptions::validate() const {
  auto positive = [](double v, const char* name) {
    if (!(v > 0) || !std::isfinite(v)) {
      throw std::invalid_argument(fmt::format("ReplayOptions.{} must be > 0, got {}", name, v));
    }
  };
  if (!std::isnan(model_sample_rate_hz)) positive(model_sample_rate_hz, "model_sample_rate_hz");
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
  log::LogReader reader(path);
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
