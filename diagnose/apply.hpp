// diagnose --apply: the selected effects written into the model, one typed parameter at a time
// (a switch over Param; nothing is parsed back from text). docs/compare.md section 5.
#pragma once

#include <string>
#include <vector>

#include "diagnose/compare.hpp"

namespace driftless::diagnose {

/// The model's current value of a parameter (file units).
double model_value(const CompareModel& m, const ParamRef& p);

/// What --apply wrote and what it could not.
struct ApplyReport {
  std::vector<std::string> written;  // "scale_factor: s1.x.value_pct = 3.01 %"
  std::vector<std::string> skipped;  // "flip_transient: not writable: ..." / "absurd: ..."
  bool complete() const { return skipped.empty(); }
};

/// Writes every selected effect (physical, box, signal chain, ADC) and every noise-model change
/// of `r` into `m`: supported parameters only (an absurd fit or an effect no model key holds is
/// skipped and listed). Each parameter's new value is the model's value plus the fitted change.
ApplyReport apply_result(CompareModel& m, const CompareResult& r);

/// Writes one candidate's parameters (used by apply_result; tests).
ApplyReport apply_candidate(CompareModel& m, const Candidate& c);

}  // namespace driftless::diagnose
