// Small helpers the compare/diagnose tests share to read a result.
#pragma once

#include <string>

#include "diagnose/compare.hpp"

namespace driftless::diagnose::check {

/// The first selected effect, else the first noise-model change; a default candidate if none.
inline const Candidate& top(const CompareResult& r) {
  static const Candidate none;
  if (!r.selected.empty()) return r.selected.front();
  if (!r.noise_model.empty()) return r.noise_model.front();
  return none;
}
/// Its catalogue id, or "" when nothing was found.
inline std::string top_effect(const CompareResult& r) {
  if (r.selected.empty() && r.noise_model.empty()) return "";
  return effect_id(top(r).effect);
}
/// The value of parameter `name` in candidate `c` (its new value), NaN with a test failure if absent.
inline double param(const Candidate& c, const std::string& name) {
  const FittedParam* p = find_param(c, name);
  if (!p) {
    ADD_FAILURE() << "no parameter " << name << " in " << effect_id(c.effect);
    return std::nan("");
  }
  return p->new_value();
}

}  // namespace driftless::diagnose::check
