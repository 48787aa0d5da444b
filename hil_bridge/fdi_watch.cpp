// The live fault detection (see fdi_watch.hpp).
#include "hil_bridge/fdi_watch.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "estimator/fdi_input.hpp"

namespace driftless::hil {

const char* to_string(FdiVerdict v) {
  switch (v) {
    case FdiVerdict::kNotMonitored: return "not-monitored";
    case FdiVerdict::kHealthy: return "healthy";
    case FdiVerdict::kAlarm: return "alarm";
    case FdiVerdict::kFault: return "fault";
    case FdiVerdict::kUncalibrated: return "uncalibrated";
  }
  return "?";
}

FdiWatch::FdiWatch(const est::FdiParams& params, double end_margin_s)
    : params_(params),
      fdi_(params),
      margin_samples_(static_cast<std::size_t>(std::lround(std::max(0.0, end_margin_s) * params.sample_rate_hz))) {}

std::string FdiWatch::push(const Sample& s, est::PushStatus status, const est::DriftlessFilter& filter) {
  if (last_ == est::FdiStatus::kIsolated) return {};  // single fault: latched (docs/fdi.md)
  est::FdiInput in = est::fdi_input(s, status, filter);
  // motion: the held rest samples may already carry it (the switch opens late): not at rest
  if (!in.at_rest) {
    for (est::FdiInput& h : held_) h.at_rest = false;
  }
  held_.push_back(in);
  std::string text;
  while (held_.size() > (in.at_rest ? margin_samples_ : 0)) {
    const std::string e = feed(held_.front());
    held_.pop_front();
    if (text.empty()) text = e;
    if (last_ == est::FdiStatus::kIsolated) {
      held_.clear();
      break;
    }
  }
  return text;
}

std::string FdiWatch::feed(const est::FdiInput& in) {
  if (in.at_rest) ++rest_samples_;
  last_ = fdi_.push(in);
  char text[512];
  if (last_ == est::FdiStatus::kIsolated && fdi_.fault()) {
    return "fdi: fault isolated: " + fdi_.fault()->describe();
  }
  if (!explained_ && fdi_.uncalibrated()) {
    explained_ = true;
    return "fdi: uncalibrated: " + fdi_.uncalibrated()->describe() +
           "; run with self_calibration (--estimator-config) or --calib";
  }
  if (!alarmed_ && fdi_.first_alarm_s()) {
    alarmed_ = true;
    std::snprintf(text, sizeof text, "fdi: alarm at t=%.3f s: the residual left its noise band (isolating)",
                  *fdi_.first_alarm_s());
    return text;
  }
  if (!learned_ && last_ != est::FdiStatus::kLearning) {
    learned_ = true;
    t_learned_s_ = in.t_s;
    const Eigen::Vector3d sig = fdi_.residual_sigma_longrun_dps();
    std::snprintf(text, sizeof text,
                  "fdi: monitoring from t=%.3f s (residual noise learned from t=%.3f s, after the filter locked at "
                  "t=%.3f s, on %ld %srest samples: long-run sigma %.4f %.4f %.4f deg/s)",
                  in.t_s, fdi_.t_learn_start_s(), fdi_.t_filter_locked_s(), fdi_.learned_samples(),
                  fdi_.learned_on_quiet() ? "quiet " : "", sig.x(), sig.y(), sig.z());
    return text;
  }
  return {};
}

FdiVerdict FdiWatch::verdict() const {
  if (fdi_.fault()) return FdiVerdict::kFault;
  if (fdi_.uncalibrated()) return FdiVerdict::kUncalibrated;
  if (fdi_.first_alarm_s()) return FdiVerdict::kAlarm;
  return learned_ ? FdiVerdict::kHealthy : FdiVerdict::kNotMonitored;
}

}  // namespace driftless::hil
