#include "diagnose/compare_model.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <stdexcept>

#include <fmt/core.h>
#include <mujoco/mujoco.h>

#include "estimator/geometry.hpp"
#include "estimator/input_error.hpp"
#include "estimator/output_file.hpp"
#include "twin/motion.hpp"
#include "twin/world.hpp"
#include "twin/yaml_doc.hpp"

namespace driftless::diagnose {

using namespace driftless::twin;  // the sensor model, box and scenario types

ModelConfig CompareModel::config() const {
  ModelConfig c;
  c.box = box;
  c.sensor1 = sensor[0];
  c.sensor2 = sensor[1];
  c.time_offset_s = time_offset_s;
  return c;
}

namespace {

// no run-to-run spread of the calibration-type effects: their values are fixed as written
void clear_calibration_spread(SensorParams& p) {
  p.scale_factor.sigma_pct.setZero();
  p.misalignment.sigma_pct = 0.0;
  p.g_sensitivity.sigma_dps_per_g = 0.0;
  p.temperature.bias_tc_sigma_dps_per_degc.setZero();
  p.temperature.scale_tc_sigma_pct_per_degc.setZero();
  p.mounting_misalignment.sigma_deg.setZero();
}

}  // namespace

SensorParams nominal_mpu6050() {
  SensorParams p = mpu6050_defaults();
  clear_calibration_spread(p);
  return p;
}

CompareModel default_compare_model() {
  CompareModel m;
  m.sensor = {nominal_mpu6050(), nominal_mpu6050()};
  m.source = "embedded nominal MPU6050";
  return m;
}

CompareModel load_compare_model(const std::filesystem::path& path) {
  // a file holding only `model:` is a model config; anything else is a scenario. Both go
  // through twin-core's parser, so every key a user can write is honoured (or refused there).
  const fields::Node root = load_yaml_file(path);
  if (!root.is_map() || root.find("model") == nullptr) {
    throw InputError(path.string(), 0, "model",
                     "missing (a model file is a scenario, or a file holding only 'model: {box: ..., "
                     "sensor1: ..., sensor2: ...}'; see docs/compare.md)");
  }
  CompareModel m;
  m.source = path.string();
  ModelConfig cfg;
  if (root.entries.size() == 1) {
    cfg = load_model_config(path, ModelConfig{});
  } else {
    m.scenario = load_scenario(path.string());
    m.is_scenario = true;
    cfg = m.scenario.model;
    m.sample_rate_hz = m.scenario.sample_rate_hz;
    m.latitude_deg = m.scenario.latitude_deg;
  }
  m.sensor = {cfg.sensor1, cfg.sensor2};
  m.box = cfg.box;
  m.time_offset_s = cfg.time_offset_s;
  return m;
}

void save_compare_model(const CompareModel& m, const std::filesystem::path& path) {
  Scenario sc = m.is_scenario ? m.scenario : Scenario{};
  sc.model = m.config();
  if (m.is_scenario && std::isfinite(m.latitude_deg)) sc.latitude_deg = m.latitude_deg;
  sc.validate();
  std::string text = emit_scenario(sc);
  if (!m.is_scenario) {
    // a model-only file stays one: only the `model:` block
    fields::Node top = fields::Node::map();
    top.add("model", model_node(sc.model));
    text = to_yaml(top);
  }
  io::write_file(path, "# written by driftless diagnose --apply (docs/compare.md)\n" + text + "\n");
}

SensorParams deterministic_part(const SensorParams& p) {
  SensorParams d = p;
  d.constant_bias.sigma_dps.setZero();
  clear_calibration_spread(d);
  d.bias_instability.enabled = false;
  d.rate_random_walk.enabled = false;
  d.white_noise.enabled = false;
  d.sample_jitter.enabled = false;
  d.quantization.enabled = false;
  d.adc_missing_codes.enabled = false;
  return d;
}


Eigen::Matrix2d settled_stop_offsets_deg(const BoxParams& box) {
  // the servo's reference runs past the stop by the overtravel (twin/flip_schedule.cpp), so the
  // platform presses into MuJoCo's soft stop: settle each platform on each stop, level box held
  // still, and read how far past (nominal + error) it rests
  Eigen::Matrix2d out = Eigen::Matrix2d::Zero();
  World world(box, 0.001, ModelScope::physics);
  const MotionState held;  // level box at the origin, at rest
  for (int side : {-1, 1}) {
    mj_resetData(world.model(), world.data());
    // start just short of the stop: the servo drives it on and presses, as after a flip
    for (int i = 1; i <= 2; ++i) world.set_platform(i, box.stop_rad(i, side) - side * 0.2 * kRadPerDeg, 0.0);
    const Eigen::Vector2d ref = Eigen::Vector2d::Constant(side * (box.end_stop_deg + box.motor.overtravel_deg) * kRadPerDeg);
    const int steps = 3000, average_from = 2000;  // 3 s at 1 ms; the last second averaged
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    for (int step = 0; step < steps; ++step) {
      world.step_driven(0.0, held, ref, false);
      if (step >= average_from) {
        for (int i = 1; i <= 2; ++i) sum[i - 1] += world.platform_angle_rad(i) - box.stop_rad(i, side);
      }
    }
    for (int i = 1; i <= 2; ++i) out(i - 1, side > 0 ? 1 : 0) = sum[i - 1] / (steps - average_from) * kDegPerRad;
  }
  return out;
}

int on_stop_side(const Replay& r, int s, std::size_t k, const BoxParams& box) {
  if (r.encoder_readback) return 0;  // an encoder reports the true angle, errors included
  const double ang = r.plat_deg[s][k];
  if (!std::isfinite(ang) || r.flipping[k]) return 0;
  if (std::abs(std::abs(ang) - box.end_stop_deg) > 0.01) return 0;
  return ang > 0 ? 1 : -1;
}

SensorPrediction predict_sensor(const Replay& r, int s, const SensorParams& p, const BoxParams& box,
                                double time_offset_s, const Eigen::Matrix2d& settled_offset_deg) {
  const SensorParams d = deterministic_part(p);
  const SensorInstance inst = draw_sensor_instance(d, 0);
  const TemperatureModel temp(d.temperature);
  SensorPrediction out;
  const std::size_t n = r.size();
  out.gyro_dps.resize(n);
  out.temp_c.resize(n);
  out.temp_from_log = r.has_temp;
  // the DLPF exactly as the sensor model runs it
  LowpassFilter lp;
  if (d.lowpass_latency.enabled) {
    const DlpfSetting set = lowpass_setting(d.lowpass_latency);
    lp = LowpassFilter(design_lowpass(set.gyro_bandwidth_hz, set.gyro_delay_s, r.sample_rate_hz));
  }
  // end-stop errors: the platform rests at nominal + error, so the sensor frame is turned by
  // the error about the hinge axis relative to the logged angle (twin/world.hpp stop_rad)
  const Eigen::Vector2d err = (s == 0 ? box.stop1_error_deg : box.stop2_error_deg) +
                              Eigen::Vector2d(settled_offset_deg.row(s).transpose());  // [-stop, +stop]
  const Eigen::Matrix3d Rt_minus = geo::rot_about_axis_deg(r.hinge_axis[s], err[0]).transpose();
  const Eigen::Matrix3d Rt_plus = geo::rot_about_axis_deg(r.hinge_axis[s], err[1]).transpose();
  const bool stop_errors = err.cwiseAbs().maxCoeff() > 0.0;
  // time offset and the sensor's own sample delay: the sensor reads the truth of that long ago
  // (linear interpolation of the replayed truth)
  const double delay_s = time_offset_s + (d.sample_delay.enabled ? d.sample_delay.delay_s : 0.0);
  const double shift = delay_s * r.sample_rate_hz;
  // a series at the prediction's time (linear between samples), double whatever it is stored as
  auto truth_at = [&](const auto& v, std::size_t k) -> Eigen::Vector3d {
    if (shift == 0.0) return v[k].template cast<double>();
    const double x = std::clamp(static_cast<double>(k) - shift, 0.0, static_cast<double>(n - 1));
    const auto i = static_cast<std::size_t>(std::floor(x));
    const double u = x - static_cast<double>(i);
    if (i + 1 >= n || u == 0.0) return v[i].template cast<double>();
    return (1.0 - u) * v[i].template cast<double>() + u * v[i + 1].template cast<double>();
  };
  Eigen::Vector3d last_w = Eigen::Vector3d::Zero(), last_f(0, 0, kStandardGravityMps2);
  for (std::size_t k = 0; k < n; ++k) {
    double tc = r.has_temp ? r.temp_c[s][k] : kNaN;
    if (!std::isfinite(tc)) tc = temp.at(r.t_s[k]);
    out.temp_c[k] = tc;
    // while a hardware platform's angle is unknown the last truth is held (samples unused)
    Eigen::Vector3d w = truth_at(r.w_radps[s], k), f = truth_at(r.f_mps2[s], k);
    if (w.allFinite()) last_w = w;
    if (f.allFinite()) last_f = f;
    w = last_w;
    f = last_f;
    if (stop_errors) {
      const int side = on_stop_side(r, s, k, box);
      if (side != 0) {
        const Eigen::Matrix3d& Rt = side > 0 ? Rt_plus : Rt_minus;
        w = Rt * w;
        if (!r.has_accel) f = Rt * f;  // logged accelerometers already sense the true frame
      }
    }
    Eigen::Vector3d y = gyro_deterministic_radps(d, inst, w, f, tc);
    if (d.lowpass_latency.enabled) y = lp.apply(y);
    out.gyro_dps[k] = gyro_adc_radps(d, inst, y) * kDegPerRad;
  }
  return out;
}

WhiteNoiseShape white_noise_shape(const SensorParams& p, double fs, int lags) {
  WhiteNoiseShape out;
  out.rho.assign(static_cast<std::size_t>(std::max(lags, 0) + 1), 0.0);
  out.rho[0] = 1.0;
  out.variance_hz = fs;
  if (!p.lowpass_latency.enabled) return out;
  // as the sensor model: noise up to a bandwidth at or above fs/2 aliases into white noise of
  // variance N^2 2B added after the filter; below fs/2 it is added before the filter
  const double bw = lowpass_setting(p.lowpass_latency).gyro_bandwidth_hz;
  if (2.0 * bw >= fs) {
    out.variance_hz = 2.0 * bw;
    return out;
  }
  // the DLPF's pole colours it (its delay does not): a first-order autoregression
  const double a = design_lowpass(bw, lowpass_setting(p.lowpass_latency).gyro_delay_s, fs).pole;
  out.variance_hz = fs * (1.0 - a) / (1.0 + a);
  for (std::size_t l = 1; l < out.rho.size(); ++l) out.rho[l] = out.rho[l - 1] * a;
  return out;
}

double white_noise_floor_dps(const SensorParams& p, int axis, double fs) {
  if (!p.white_noise.enabled) return 0.0;
  return p.white_noise.density_dps_rthz[axis] * std::sqrt(white_noise_shape(p, fs, 0).variance_hz);
}

double block_mean_variance_ratio(const SensorParams& p, double fs, std::size_t block_len) {
  // var of a block mean of the output noise relative to that of white noise of density N
  // (N^2 fs / L): var_1 (1 + 2 sum_l (1 - l/L) rho_l) / fs
  const auto L = static_cast<int>(block_len);
  const WhiteNoiseShape w = white_noise_shape(p, fs, L);
  double v = 1.0;
  for (int l = 1; l < L; ++l) v += 2.0 * (1.0 - static_cast<double>(l) / L) * w.rho[static_cast<std::size_t>(l)];
  return w.variance_hz * v / fs;
}

double dlpf_lag1_autocorrelation(const SensorParams& p, double fs) { return white_noise_shape(p, fs, 1).rho[1]; }

}  // namespace driftless::diagnose
