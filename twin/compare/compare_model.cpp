#include "twin/compare/compare_model.hpp"

#include <cmath>
#include <fstream>
#include <stdexcept>

#include <fmt/core.h>

namespace driftless::twin {

CompareModel default_compare_model() {
  CompareModel m;
  m.sensor = {mpu6050_defaults(), mpu6050_defaults()};
  m.sample_rate_hz = 100.0;
  m.source = "embedded MPU6050 defaults";
  return m;
}

CompareModel load_compare_model(const std::filesystem::path& path) {
  CompareModel m;
  m.source = path.string();
  m.sensor = {mpu6050_defaults(), mpu6050_defaults()};
  try {
    m.root = YAML::LoadFile(path.string());
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(fmt::format("{}:{}: {}", path.string(), e.mark.line + 1, e.msg));
  }
  if (!m.root.IsMap()) {
    throw std::runtime_error(fmt::format("{}: expected a YAML map with a 'model:' key", path.string()));
  }
  YAML::Node model = m.root["model"];
  if (!model) {
    throw std::runtime_error(fmt::format(
        "{}: no 'model:' key (a model file holds 'model: {{sensor1: ..., sensor2: ...}}', see "
        "docs/compare.md)",
        path.string()));
  }
  for (int s = 0; s < 2; ++s) {
    const std::string key = s == 0 ? "sensor1" : "sensor2";
    YAML::Node node = model[key];
    if (node) m.sensor[s] = parse_sensor_params(node, mpu6050_defaults(), path.string());
  }
  auto number = [&](const char* key) {
    YAML::Node n = m.root[key];
    if (!n) return kNaN;
    try {
      return n.as<double>();
    } catch (const YAML::Exception&) {
      throw std::runtime_error(fmt::format("{}:{}: key '{}': expected a number", path.string(),
                                           n.Mark().line + 1, key));
    }
  };
  m.sample_rate_hz = number("sample_rate_hz");
  m.latitude_deg = number("latitude_deg");
  return m;
}

void save_compare_model(const CompareModel& m, const std::filesystem::path& path) {
  YAML::Node root = m.root ? YAML::Clone(m.root) : YAML::Node(YAML::NodeType::Map);
  if (!root["model"]) root["model"] = YAML::Node(YAML::NodeType::Map);
  for (int s = 0; s < 2; ++s) {
    YAML::Emitter e;
    emit_sensor_params(e, m.sensor[s]);
    root["model"][s == 0 ? "sensor1" : "sensor2"] = YAML::Load(e.c_str());
  }
  if (std::isfinite(m.latitude_deg)) root["latitude_deg"] = m.latitude_deg;
  if (std::isfinite(m.sample_rate_hz) && !root["sample_rate_hz"]) root["sample_rate_hz"] = m.sample_rate_hz;
  YAML::Emitter out;
  out.SetDoublePrecision(10);
  out << root;
  std::ofstream f(path);
  if (!f) throw std::runtime_error(fmt::format("cannot write {}", path.string()));
  f << "# written by driftless diagnose --apply (docs/compare.md)\n" << out.c_str() << "\n";
}

SensorParams deterministic_part(const SensorParams& p) {
  SensorParams d = p;
  d.constant_bias.sigma_dps.setZero();
  d.scale_factor.sigma_pct.setZero();
  d.misalignment.sigma_pct = 0.0;
  d.g_sensitivity.sigma_dps_per_g = 0.0;
  d.temperature.bias_tc_sigma_dps_per_degc.setZero();
  d.temperature.scale_tc_sigma_pct_per_degc.setZero();
  d.mounting_misalignment.sigma_deg.setZero();
  d.bias_instability.enabled = false;
  d.rate_random_walk.enabled = false;
  d.white_noise.enabled = false;
  d.sample_jitter.enabled = false;
  d.quantization.enabled = false;
  d.adc_missing_codes.enabled = false;
  return d;
}

namespace {

// the DLPF as the sensor model runs it: first-order IIR, then a fractional delay
struct LowpassRun {
  LowpassDesign d;
  std::vector<Eigen::Vector3d> hist;
  Eigen::Vector3d u = Eigen::Vector3d::Zero();
  int head = 0;
  bool primed = false;
  Eigen::Vector3d apply(const Eigen::Vector3d& x) {
    const int n = d.delay_whole_samples;
    const int size = n + 2;
    if (!primed) {
      u = x;
      hist.assign(static_cast<std::size_t>(size), x);
      head = 0;
      primed = true;
    } else {
      u = d.pole * u + (1.0 - d.pole) * x;
      head = (head + 1) % size;
      hist[static_cast<std::size_t>(head)] = u;
    }
    const auto& a = hist[static_cast<std::size_t>((head - n + size) % size)];
    const auto& b = hist[static_cast<std::size_t>((head - n - 1 + 2 * size) % size)];
    return (1.0 - d.delay_frac) * a + d.delay_frac * b;
  }
};

std::vector<double> dlpf_impulse(const SensorParams& p, double fs) {
  std::vector<double> h;
  if (!p.lowpass_latency.enabled) return {1.0};
  const DlpfSetting set = mpu6050_dlpf(p.lowpass_latency.dlpf_cfg);
  LowpassRun lp;
  lp.d = design_lowpass(set.gyro_bandwidth_hz, set.gyro_delay_s, fs);
  lp.apply(Eigen::Vector3d::Zero());
  for (int k = 0; k < 400; ++k) h.push_back(lp.apply(Eigen::Vector3d::Constant(k == 0 ? 1.0 : 0.0))[0]);
  return h;
}

}  // namespace

SensorPrediction predict_sensor(const Replay& r, int s, const SensorParams& p) {
  const SensorParams d = deterministic_part(p);
  const SensorInstance inst = draw_sensor_instance(d, 0);
  const TemperatureModel temp(d.temperature);
  SensorPrediction out;
  const std::size_t n = r.size();
  out.gyro_dps.resize(n);
  out.temp_c.resize(n);
  out.temp_from_log = r.has_temp;
  LowpassRun lp;
  if (d.lowpass_latency.enabled) {
    const DlpfSetting set = mpu6050_dlpf(d.lowpass_latency.dlpf_cfg);
    lp.d = design_lowpass(set.gyro_bandwidth_hz, set.gyro_delay_s, r.sample_rate_hz);
  }
  Eigen::Vector3d last_w = Eigen::Vector3d::Zero(), last_f(0, 0, kStandardGravityMps2);
  for (std::size_t k = 0; k < n; ++k) {
    double tc = r.has_temp ? r.temp_c[s][k] : kNaN;
    if (!std::isfinite(tc)) tc = temp.at(r.t_s[k]);
    out.temp_c[k] = tc;
    // while a hardware platform's angle is unknown the last truth is held (samples unused)
    if (r.w_radps[s][k].allFinite()) last_w = r.w_radps[s][k];
    if (r.f_mps2[s][k].allFinite()) last_f = r.f_mps2[s][k];
    Eigen::Vector3d y = gyro_deterministic_radps(d, inst, last_w, last_f, tc);
    if (d.lowpass_latency.enabled) y = lp.apply(y);
    out.gyro_dps[k] = gyro_adc_radps(d, inst, y) * kDegPerRad;
  }
  return out;
}

double white_noise_floor_dps(const SensorParams& p, int axis, double fs) {
  if (!p.white_noise.enabled) return 0.0;
  double g = 0.0;
  for (double h : dlpf_impulse(p, fs)) g += h * h;
  return p.white_noise.density_dps_rthz[axis] * std::sqrt(fs * g);
}

double block_mean_variance_ratio(const SensorParams& p, double fs, std::size_t block_len) {
  // var of a block mean of DLPF-filtered white noise relative to unfiltered white noise
  const auto h = dlpf_impulse(p, fs);
  const auto L = static_cast<long>(block_len);
  std::vector<double> g(static_cast<std::size_t>(L), 0.0);
  for (long l = 0; l < L; ++l)
    for (std::size_t k = 0; k + static_cast<std::size_t>(l) < h.size(); ++k) g[static_cast<std::size_t>(l)] += h[k] * h[k + static_cast<std::size_t>(l)];
  double v = static_cast<double>(L) * g[0];
  for (long l = 1; l < L; ++l) v += 2.0 * static_cast<double>(L - l) * g[static_cast<std::size_t>(l)];
  return v / static_cast<double>(L);
}

double dlpf_lag1_autocorrelation(const SensorParams& p, double fs) {
  const auto h = dlpf_impulse(p, fs);
  double g0 = 0.0, g1 = 0.0;
  for (std::size_t k = 0; k < h.size(); ++k) {
    g0 += h[k] * h[k];
    if (k + 1 < h.size()) g1 += h[k] * h[k + 1];
  }
  return g0 > 0 ? g1 / g0 : 0.0;
}

}  // namespace driftless::twin
