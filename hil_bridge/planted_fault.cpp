// Planted sensor faults for the emulated chips (see planted_fault.hpp).
#include "hil_bridge/planted_fault.hpp"

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <vector>

#include "estimator/sample.hpp"

namespace driftless::hil {
namespace {

constexpr const char* kForm = "expected stuck:S:A@T or bias:S:A:DPS@T (S 1|2, A x|y|z, DPS deg/s, T s)";

[[noreturn]] void bad(const std::string& spec, const std::string& what) {
  throw std::invalid_argument("--emu-fault '" + spec + "': " + what + "; " + kForm);
}

double number(const std::string& spec, const std::string& text, const char* what) {
  std::size_t used = 0;
  double v = kNaN;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size() || !std::isfinite(v)) bad(spec, std::string(what) + " '" + text + "' is not a number");
  return v;
}

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out(1);
  for (char c : s) {
    if (c == sep) {
      out.emplace_back();
    } else {
      out.back().push_back(c);
    }
  }
  return out;
}

}  // namespace

std::string PlantedFault::describe() const {
  if (kind == Kind::kNone) return "none";
  char what[48] = "stuck";
  if (kind == Kind::kBias) std::snprintf(what, sizeof what, "bias %+g deg/s", bias_dps);
  char out[128];
  std::snprintf(out, sizeof out, "%s on sensor %d axis %c from t=%g s", what, sensor, "xyz"[axis], t_s);
  return out;
}

PlantedFault parse_planted_fault(const std::string& spec) {
  const auto at = spec.rfind('@');
  if (at == std::string::npos) bad(spec, "no '@T' onset");
  PlantedFault f;
  f.t_s = number(spec, spec.substr(at + 1), "onset T");
  if (f.t_s < 0) bad(spec, "onset T must be >= 0 s");
  const std::vector<std::string> parts = split(spec.substr(0, at), ':');
  if (parts[0] == "stuck" && parts.size() == 3) {
    f.kind = PlantedFault::Kind::kStuck;
  } else if (parts[0] == "bias" && parts.size() == 4) {
    f.kind = PlantedFault::Kind::kBias;
    f.bias_dps = number(spec, parts[3], "bias DPS");
  } else {
    bad(spec, "unknown kind or wrong number of fields");
  }
  if (parts[1] != "1" && parts[1] != "2") bad(spec, "sensor '" + parts[1] + "' is not 1 or 2");
  f.sensor = parts[1] == "1" ? 1 : 2;
  if (parts[2].size() != 1 || parts[2].find_first_of("xyz") != 0) bad(spec, "axis '" + parts[2] + "' is not x, y or z");
  f.axis = parts[2][0] - 'x';
  return f;
}

FaultyGenerator::FaultyGenerator(std::unique_ptr<ImuGenerator> inner, PlantedFault fault)
    : inner_(std::move(inner)), fault_(fault) {}

ImuReading FaultyGenerator::sample(int sensor, double t_s) {
  ImuReading r = inner_->sample(sensor, t_s);
  if (sensor + 1 != fault_.sensor || !fault_.planted()) return r;
  double& y = r.gyro_dps[fault_.axis];
  if (t_s < fault_.t_s) {
    held_dps_ = y;
    have_held_ = true;
    return r;
  }
  if (fault_.kind == PlantedFault::Kind::kStuck) {
    if (!have_held_) held_dps_ = y, have_held_ = true;  // onset at the first sample
    y = held_dps_;
  } else {
    y += fault_.bias_dps;
    r.true_bias_dps[fault_.axis] += fault_.bias_dps;
  }
  return r;
}

}  // namespace driftless::hil
