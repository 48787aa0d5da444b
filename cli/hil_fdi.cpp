// driftless hil --fdi outputs (see hil_fdi.hpp).
#include "cli/hil_fdi.hpp"

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
  out += "  \"first_alarm_s\": " + json_number(alarm ? *alarm : kNaN) + ",\n";
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
    case hil::FdiVerdict::kNotMonitored:
      fmt::print(stderr,
                 "driftless hil: fdi: not monitored: {} samples at rest, fewer than the {:g} s the detector learns "
                 "the residual noise from; run longer (--duration) or with standstills (--standstill); {}\n",
                 watch.rest_samples(), watch.params().learn_s, json_path.string());
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
