#include "diagnose/apply.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/core.h>

#include "diagnose/signal_chain.hpp"
#include "diagnose/summary.hpp"

namespace driftless::diagnose {
namespace {

twin::SensorParams& sensor_of(CompareModel& m, const ParamRef& p) { return m.sensor[static_cast<std::size_t>(p.sensor)]; }
const twin::SensorParams& sensor_of(const CompareModel& m, const ParamRef& p) {
  return m.sensor[static_cast<std::size_t>(p.sensor)];
}

Eigen::Vector2d& stop_errors(CompareModel& m, int platform) {
  return platform == 0 ? m.box.stop1_error_deg : m.box.stop2_error_deg;
}

// writes the new value of one parameter; a fitted calibration-type value is now known, so its
// run-to-run spread goes to 0
void write_param(CompareModel& m, const ParamRef& p, double v) {
  const int j = p.row, k = p.col;
  switch (p.param) {
    case Param::kScalePct: {
      auto& e = sensor_of(m, p).scale_factor;
      e.enabled = true, e.value_pct[j] = v, e.sigma_pct[j] = 0.0;
      return;
    }
    case Param::kMisalignmentPct: {
      auto& e = sensor_of(m, p).misalignment;
      e.enabled = true, e.matrix_pct(j, k) = v, e.sigma_pct = 0.0;
      return;
    }
    case Param::kGSensDpsPerG: {
      auto& e = sensor_of(m, p).g_sensitivity;
      e.enabled = true, e.matrix_dps_per_g(j, k) = v, e.sigma_dps_per_g = 0.0;
      return;
    }
    case Param::kBiasTcDpsPerDegc: {
      auto& e = sensor_of(m, p).temperature;
      e.enabled = true, e.bias_tc_dps_per_degc[j] = v, e.bias_tc_sigma_dps_per_degc[j] = 0.0;
      return;
    }
    case Param::kScaleTcPctPerDegc: {
      auto& e = sensor_of(m, p).temperature;
      e.enabled = true, e.scale_tc_pct_per_degc[j] = v, e.scale_tc_sigma_pct_per_degc[j] = 0.0;
      return;
    }
    case Param::kNonlinQuadPctFs: sensor_of(m, p).adc_nonlinearity.enabled = true, sensor_of(m, p).adc_nonlinearity.quadratic_pct_fs = v; return;
    case Param::kNonlinCubicPctFs: sensor_of(m, p).adc_nonlinearity.enabled = true, sensor_of(m, p).adc_nonlinearity.cubic_pct_fs = v; return;
    case Param::kMountingDeg: {
      auto& e = sensor_of(m, p).mounting_misalignment;
      e.enabled = true, e.angles_deg[j] = v, e.sigma_deg[j] = 0.0;
      return;
    }
    case Param::kStopErrorDeg: stop_errors(m, p.sensor)[k] = v; return;
    case Param::kLatitudeDeg: m.latitude_deg = v; return;
    case Param::kLowpassDelayS: {
      // a delay at the "no low-pass" boundary is written as no filter: a filter of microseconds
      // takes its bandwidth from the datasheet relation (tens of kHz), and simulate would alias
      // the white noise from there
      const double d = v <= kNoLowpassDelayS ? 0.0 : v;
      for (int s = 0; s < 2; ++s)
        if (p.sensor < 0 || p.sensor == s) m.sensor[static_cast<std::size_t>(s)] = with_lowpass_delay(m.sensor[static_cast<std::size_t>(s)], d);
      return;
    }
    case Param::kSampleDelayS: sensor_of(m, p).sample_delay.enabled = v > 0.0, sensor_of(m, p).sample_delay.delay_s = v; return;
    case Param::kTimeOffsetS: m.time_offset_s = v; return;
    case Param::kQuantLsbPerDps: {
      // 0: the outputs lie on no lattice, the model's quantisation is removed (writing 0 LSB per
      // deg/s was refused by the model's own check: --apply failed on every log without an ADC)
      auto& q = sensor_of(m, p).quantization;
      q.enabled = v > 0.0;
      if (v > 0.0) q.sensitivity_lsb_per_dps = v;
      return;
    }
    case Param::kFullScaleDps: sensor_of(m, p).saturation.enabled = true, sensor_of(m, p).saturation.full_scale_dps = v; return;
    case Param::kConstantBiasDps: {
      auto& e = sensor_of(m, p).constant_bias;
      e.enabled = true, e.value_dps[j] = v, e.sigma_dps[j] = 0.0;
      return;
    }
    case Param::kWhiteDensity: sensor_of(m, p).white_noise.enabled = true, sensor_of(m, p).white_noise.density_dps_rthz[j] = v; return;
    case Param::kGmSigmaDps: sensor_of(m, p).bias_instability.enabled = true, sensor_of(m, p).bias_instability.sigma_dps[j] = v; return;
    case Param::kGmTauS: sensor_of(m, p).bias_instability.tau_s[j] = v; return;
    case Param::kRrwDpsRts: sensor_of(m, p).rate_random_walk.enabled = true, sensor_of(m, p).rate_random_walk.k_dps_rts[j] = v; return;
    case Param::kJitterSigmaS: sensor_of(m, p).sample_jitter.enabled = v > 0.0, sensor_of(m, p).sample_jitter.sigma_s = v; return;
    case Param::kFlipTransientDps:
    case Param::kMissingCodes:
    case Param::kDelaySecondOrderS2:
    case Param::kDelayThirdOrderS3:
    case Param::kNoiseLag1:
    case Param::kModelLag1: return;  // written elsewhere (codes) or never
  }
}

// the ADC nonlinearity is one pair of coefficients per sensor: the mean over the axes fitted
void average_nonlinearity(std::vector<FittedParam>& params) {
  for (Param which : {Param::kNonlinQuadPctFs, Param::kNonlinCubicPctFs}) {
    for (int s = 0; s < 2; ++s) {
      double sum = 0.0;
      int n = 0;
      for (const auto& fp : params)
        if (fp.ref.param == which && fp.ref.sensor == s) sum += fp.new_value(), ++n;
      for (auto& fp : params)
        if (fp.ref.param == which && fp.ref.sensor == s) fp.value = sum / n - fp.model_value;
    }
  }
}

std::string written_line(const Candidate& c, const FittedParam& fp) {
  if (is_no_lowpass(fp))
    return fmt::format("{}: {}: no low-pass (enabled: false)", effect_id(c.effect), fp.name());
  if (removes_model_effect(fp)) return fmt::format("{}: {}: removed (enabled: false)", effect_id(c.effect), fp.name());
  return fmt::format("{}: {} = {:.6g} {}", effect_id(c.effect), fp.name(), fp.new_value(), fp.unit());
}

}  // namespace

double model_value(const CompareModel& m, const ParamRef& p) {
  const int j = p.row, k = p.col;
  switch (p.param) {
    case Param::kScalePct: return sensor_of(m, p).scale_factor.enabled ? sensor_of(m, p).scale_factor.value_pct[j] : 0.0;
    case Param::kMisalignmentPct: return sensor_of(m, p).misalignment.enabled ? sensor_of(m, p).misalignment.matrix_pct(j, k) : 0.0;
    case Param::kGSensDpsPerG: return sensor_of(m, p).g_sensitivity.enabled ? sensor_of(m, p).g_sensitivity.matrix_dps_per_g(j, k) : 0.0;
    case Param::kBiasTcDpsPerDegc: return sensor_of(m, p).temperature.enabled ? sensor_of(m, p).temperature.bias_tc_dps_per_degc[j] : 0.0;
    case Param::kScaleTcPctPerDegc: return sensor_of(m, p).temperature.enabled ? sensor_of(m, p).temperature.scale_tc_pct_per_degc[j] : 0.0;
    case Param::kNonlinQuadPctFs: return sensor_of(m, p).adc_nonlinearity.enabled ? sensor_of(m, p).adc_nonlinearity.quadratic_pct_fs : 0.0;
    case Param::kNonlinCubicPctFs: return sensor_of(m, p).adc_nonlinearity.enabled ? sensor_of(m, p).adc_nonlinearity.cubic_pct_fs : 0.0;
    case Param::kMountingDeg: return sensor_of(m, p).mounting_misalignment.enabled ? sensor_of(m, p).mounting_misalignment.angles_deg[j] : 0.0;
    case Param::kStopErrorDeg: return (p.sensor == 0 ? m.box.stop1_error_deg : m.box.stop2_error_deg)[k];
    case Param::kLatitudeDeg: return std::isfinite(m.latitude_deg) ? m.latitude_deg : 0.0;
    case Param::kLowpassDelayS: return lowpass_delay_s(m.sensor[p.sensor < 0 ? 0 : static_cast<std::size_t>(p.sensor)]);
    case Param::kSampleDelayS: return sensor_of(m, p).sample_delay.enabled ? sensor_of(m, p).sample_delay.delay_s : 0.0;
    case Param::kTimeOffsetS: return m.time_offset_s;
    case Param::kQuantLsbPerDps: return sensor_of(m, p).quantization.enabled ? sensor_of(m, p).quantization.sensitivity_lsb_per_dps : 0.0;
    case Param::kFullScaleDps: return sensor_of(m, p).saturation.enabled ? sensor_of(m, p).saturation.full_scale_dps : 0.0;
    case Param::kConstantBiasDps: return sensor_of(m, p).constant_bias.enabled ? sensor_of(m, p).constant_bias.value_dps[j] : 0.0;
    case Param::kWhiteDensity: return sensor_of(m, p).white_noise.enabled ? sensor_of(m, p).white_noise.density_dps_rthz[j] : 0.0;
    case Param::kGmSigmaDps: return sensor_of(m, p).bias_instability.enabled ? sensor_of(m, p).bias_instability.sigma_dps[j] : 0.0;
    case Param::kGmTauS: return sensor_of(m, p).bias_instability.tau_s[j];
    case Param::kRrwDpsRts: return sensor_of(m, p).rate_random_walk.enabled ? sensor_of(m, p).rate_random_walk.k_dps_rts[j] : 0.0;
    case Param::kJitterSigmaS: return sensor_of(m, p).sample_jitter.enabled ? sensor_of(m, p).sample_jitter.sigma_s : 0.0;
    case Param::kFlipTransientDps:
    case Param::kMissingCodes:
    case Param::kDelaySecondOrderS2:
    case Param::kDelayThirdOrderS3:
    case Param::kNoiseLag1:
    case Param::kModelLag1: return 0.0;
  }
  return 0.0;
}

ApplyReport apply_candidate(CompareModel& m, const Candidate& c) {
  ApplyReport rep;
  const EffectInfo& info = effect_info(c.effect);
  if (!info.writable) {
    rep.skipped.push_back(fmt::format("{}: no model key holds it: {}", info.id, info.not_writable_because));
    return rep;
  }
  if (c.absurd) {
    rep.skipped.push_back(fmt::format("{}: not written, its fit is implausible (check the log's units, axes and "
                                      "frame convention, docs/log-format.md)", info.id));
    return rep;
  }
  if (c.effect == Effect::kEarthRate && !std::isfinite(m.latitude_deg)) {
    const double d = c.params.empty() ? 0.0 : c.params.front().value;
    rep.skipped.push_back(fmt::format("earth_rate: the model file states no latitude_deg to correct; set it "
                                      "(or the log's) by {:+.3f} deg", d));
    return rep;
  }
  std::vector<FittedParam> params = c.params;
  if (c.effect == Effect::kAdcNonlinearity) average_nonlinearity(params);
  for (const auto& fp : params) {
    write_param(m, fp.ref, is_no_lowpass(fp) ? 0.0 : fp.new_value());
    rep.written.push_back(written_line(c, fp));
  }
  for (const auto& [channel, code] : c.codes) {
    auto& mc = m.sensor[static_cast<std::size_t>(channel / 3)].adc_missing_codes;
    mc.enabled = true;
    mc.fraction = 0.0;
    if (std::find(mc.codes.begin(), mc.codes.end(), code) == mc.codes.end()) mc.codes.push_back(code);
    std::sort(mc.codes.begin(), mc.codes.end());
  }
  if (!c.codes.empty()) rep.written.push_back(fmt::format("adc_missing_codes: {} codes", c.codes.size()));
  return rep;
}

ApplyReport apply_result(CompareModel& m, const CompareResult& r) {
  ApplyReport rep;
  for (const auto* list : {&r.selected, &r.noise_model}) {
    for (const Candidate& c : *list) {
      const ApplyReport one = apply_candidate(m, c);
      rep.written.insert(rep.written.end(), one.written.begin(), one.written.end());
      rep.skipped.insert(rep.skipped.end(), one.skipped.begin(), one.skipped.end());
    }
  }
  return rep;
}

}  // namespace driftless::diagnose
