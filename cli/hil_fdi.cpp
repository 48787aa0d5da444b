// driftless hil --fdi outputs (see hil_fdi.hpp).
#include "cli/hil_fdi.hpp"

#include <cmath>
#include <cstdio>
#include <string>

#include <fmt/core.h>

#include "estimator/output_file.hpp"
#include "report/json.hpp"

namespace driftless::cli {
namespace {

using report::json_number;
using report::json_string;

std::string fault_json(const est::FaultReport& f) {
  // the magnitude's unit depends on the kind (docs/fdi.md, FaultReport)
  const char* unit = f.kind == est::FaultKind::kStuck          ? "deg/s (the value the axis is stuck at)"
                     : f.kind == est::FaultKind::kBiasStep      ? "deg/s"
                     : f.kind == est::FaultKind::kScaleChange ? "relative gain change"
                     : f.kind == est::FaultKind::kNoiseBurst  ? "variance ratio"
                                                              : "";
  return fmt::format(
      "{{\"kind\": {}, \"sensor\": {}, \"axis\": {}, \"t_alarm_s\": {}, \"t_isolated_s\": {}, \"t_onset_s\": {}, "
      "\"magnitude\": {}, \"magnitude_unit\": {}, \"confident\": {}, \"sensor_ambiguous\": {}}}",
      json_string(est::to_string(f.kind)), f.sensor, json_string(std::string(1, "xyz"[f.axis])),
      json_number(f.t_alarm_s), json_number(f.t_isolated_s), json_number(f.t_onset_s), json_number(f.magnitude),
      json_string(unit), f.confident ? "true" : "false", f.sensor_ambiguous ? "true" : "false");
}

// when and on what the residual noise was learned (docs/fdi.md, "Learning the noise")
std::string learning_json(const est::FaultDetector& d) {
  const est::FdiParams& p = d.params();
  return fmt::format(
      "{{\"filter_locked_s\": {}, \"started_s\": {}, \"samples\": {}, \"segments\": {}, \"on\": {}}}",
      json_number(d.t_filter_locked_s()), json_number(d.t_learn_start_s()), d.learned_samples(), d.learned_segments(),
      json_string(d.learned_on_quiet()
                      ? fmt::format("quiet rest samples (both platforms still, the filter in a standstill, box rate "
                                    "<= {:g} deg/s) after the filter locked (its estimate's sigma in the residual < "
                                    "{:g} deg/s)",
                                    p.quiet_rate_dps, p.lock_sigma_dps)
                      : fmt::format("rest samples (both platforms still, the filter in a standstill; the box turned "
                                    "faster than {:g} deg/s in most of them) after the filter locked (its estimate's "
                                    "sigma in the residual < {:g} deg/s)",
                                    p.quiet_rate_dps, p.lock_sigma_dps)));
}

std::string uncalibrated_json(const est::UncalibratedReport& u) {
  return fmt::format(
      "{{\"t_alarm_s\": {}, \"t_decided_s\": {}, \"offset_dps\": {}, \"change_dps\": {}, \"step_chi2\": {}, "
      "\"segments\": {}, \"alarms_explained\": {}, \"while_turning\": {}, \"cause\": {}, \"fix\": {}}}",
      json_number(u.t_alarm_s), json_number(u.t_decided_s), json_number(u.offset_dps), json_number(u.change_dps),
      json_number(u.step_chi2), u.segments, u.alarms, u.while_turning,
      json_string("the residual's offset follows the platform positions (the same at every visit): g-sensitivity, "
                  "misalignment or scale errors of uncalibrated sensors, not a fault"),
      json_string("run with self_calibration: true in --estimator-config, or with --calib from driftless calibrate"));
}

}  // namespace

void write_fdi_json(const std::filesystem::path& path, const hil::FdiWatch& watch) {
  const est::FaultDetector& d = watch.detector();
  const Eigen::Vector3d sig = d.residual_sigma_longrun_dps();
  const auto alarm = d.first_alarm_s();
  std::string out = "{\n  \"format\": \"driftless-fdi 1\",\n";
  out += "  \"verdict\": " + json_string(hil::to_string(watch.verdict())) + ",\n";
  out += "  \"monitoring_from_s\": " + json_number(watch.t_learned_s()) + ",\n";
  out += "  \"rest_samples\": " + std::to_string(watch.rest_samples()) + ",\n";
  out += "  \"residual_sigma_longrun_dps\": " + report::json_array({sig.x(), sig.y(), sig.z()}) + ",\n";
  out += "  \"learning\": " + learning_json(d) + ",\n";
  out += "  \"first_alarm_s\": " + json_number(alarm ? *alarm : kNaN) + ",\n";
  out += "  \"uncalibrated\": " + (d.uncalibrated() ? uncalibrated_json(*d.uncalibrated()) : std::string("null")) + ",\n";
  out += "  \"fault\": " + (d.fault() ? fault_json(*d.fault()) : std::string("null")) + "\n}\n";
  io::write_file(path, out);
}

int report_fdi(const hil::FdiWatch& watch, const std::filesystem::path& json_path) {
  const est::FaultDetector& d = watch.detector();
  switch (watch.verdict()) {
    case hil::FdiVerdict::kHealthy:
      fmt::print("fdi: healthy: no alarm from t={:.2f} s on ({} samples at rest tested); {}\n", watch.t_learned_s(),
                 watch.rest_samples(), json_path.string());
      return 0;
    case hil::FdiVerdict::kUncalibrated:
      fmt::print(stderr,
                 "driftless hil: fdi: uncalibrated, no fault: {}; run with self_calibration (--estimator-config) or "
                 "--calib; {}\n",
                 d.uncalibrated()->describe(), json_path.string());
      return 0;
    case hil::FdiVerdict::kNotMonitored:
      fmt::print(stderr,
                 "driftless hil: fdi: not monitored: {} samples at rest; the detector learns the residual noise "
                 "from {:g} s of quiet rest samples once the filter has locked ({}); run longer (--duration) or with "
                 "standstills (--standstill); {}\n",
                 watch.rest_samples(), watch.params().learn_s,
                 std::isnan(d.t_filter_locked_s()) ? std::string("it never locked")
                                                   : fmt::format("locked at t={:.2f} s", d.t_filter_locked_s()),
                 json_path.string());
      return 1;
    case hil::FdiVerdict::kAlarm:
      fmt::print(stderr,
                 "driftless hil: fdi: alarm at t={:.3f} s, not isolated to a sensor by the end of the run (it "
                 "needs up to two flips); check both sensors, run longer to isolate it; {}\n",
                 *d.first_alarm_s(), json_path.string());
      return 1;
    case hil::FdiVerdict::kFault: {
      const est::FaultReport& f = *d.fault();
      fmt::print(stderr,
                 "driftless hil: fdi: {}; sensor {} is faulty: replace or re-seat it (sensor {} alone carries the "
                 "box rate meanwhile, docs/fdi.md 'Fault-tolerant mode'); {}\n",
                 f.describe(), f.sensor, 3 - f.sensor, json_path.string());
      return 1;
    }
  }
  return 1;
}

}  // namespace driftless::cli
