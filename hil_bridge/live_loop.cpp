#include "hil_bridge/live_loop.hpp"

#include "estimator/health.hpp"

#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace driftless::hil {

void LiveParams::validate() const {
  if (!(duration_s > 0.0)) throw std::invalid_argument("hil: duration must be > 0 s");
  if (!std::isnan(switch_at_s) && !(switch_at_s > 0.0)) throw std::invalid_argument("hil: --at must be > 0 s");
  if (!(reconnect_interval_s > 0.0)) throw std::invalid_argument("hil: reconnect_interval_s must be > 0 s");
  if (!(give_up_after_s > 0.0)) throw std::invalid_argument("hil: give_up_after_s must be > 0 s");
  if (!(log_flush_every_s > 0.0)) throw std::invalid_argument("hil: log_flush_every_s must be > 0 s");
}

LiveLoop::LiveLoop(LiveParams p, Clock& clock, log::LogWriter* log, est::DriftlessFilter* filter)
    : p_(p), clock_(clock), log_(log), filter_(filter), lock_(est::HealthLimits{}.lock_sigma_dps) {
  p_.validate();
}

// after a push: an update (accepted, or rejected by the gate, which may re-lock) steps the lock
void LiveLoop::step_lock(est::PushStatus pushed) {
  if (pushed != est::PushStatus::kUpdated && pushed != est::PushStatus::kRejected) return;
  stats_.sigma_at_end_dps = filter_->correction_sigma_dps().maxCoeff();
  lock_.on_update(stats_.sigma_at_end_dps, filter_->last_update().relocked);
  stats_.ever_locked = stats_.ever_locked || lock_.locked();
  stats_.locked_at_end = lock_.locked();
}

void LiveLoop::event(const std::string& text) {
  ++stats_.events;
  if (pump_) pump_->event(t_last_, text);
  if (on_event_) on_event_(t_last_, text);
}

void LiveLoop::drain(SampleSource& src) {
  if (!src.has_events()) return;
  pending_.clear();
  src.take_events(pending_);
  for (const auto& e : pending_) {
    switch (e.kind) {
      case EventKind::kBusError:
      case EventKind::kTimeout:
      case EventKind::kDisconnected:
      case EventKind::kCorruptFrame:
      case EventKind::kFifoOverflow:
        ++stats_.faults;
        break;
      default: break;
    }
    stats_.lost_samples += e.lost_samples;
    std::string text = std::string(to_string(e.kind)) + ": " + src.name() + ": " + e.text;
    if (e.lost_samples > 0) text += " [lost " + std::to_string(e.lost_samples) + "]";
    event(text);
  }
}

bool LiveLoop::reconnect(SampleSource& src, const std::atomic<bool>& stop) {
  const double t0 = clock_.now_s();
  int attempts = 0;
  while (!stop.load()) {
    clock_.sleep_for(p_.reconnect_interval_s);
    ++attempts;
    const Status s = src.reconnect();
    drain(src);
    if (s.ok()) {
      ++stats_.reconnects;
      // the device was re-initialised: a standstill in progress cannot be trusted across it
      if (filter_) filter_->on_source_switch();
      return true;
    }
    if (clock_.now_s() - t0 > p_.give_up_after_s) {
      event("disconnected: " + src.name() + ": gave up after " + std::to_string(attempts) +
            " reconnect attempts over " + std::to_string(clock_.now_s() - t0) + " s: " + s.message);
      return false;
    }
  }
  return false;
}

void LiveLoop::select_motors(const SampleSource* src) {
  motors_ = nullptr;
  schedule_ = nullptr;
  for (const auto& r : rigs_) {
    if (r.source == src) {
      motors_ = r.motors;
      schedule_ = r.schedule;
    }
  }
}

LiveStats LiveLoop::run(SampleSource& first, SampleSource* second, const std::atomic<bool>& stop) {
  if (!log_) return run_loop(first, second, stop);
  LogPump pump(*log_, p_.log_flush_every_s);
  pump_ = &pump;
  struct Unset {
    LogPump*& p;
    ~Unset() { p = nullptr; }
  } unset{pump_};
  LiveStats st = run_loop(first, second, stop);
  pump.close();  // every row in the writer (or its error, e.g. a full disk, thrown here)
  st.log_waits = pump.waits();
  return st;
}

LiveStats LiveLoop::run_loop(SampleSource& first, SampleSource* second, const std::atomic<bool>& stop) {
  stats_ = LiveStats();
  t_last_ = kNaN;
  SampleSource* src = &first;
  select_motors(src);
  const bool want_switch = second != nullptr && !std::isnan(p_.switch_at_s);
  {
    const Status s = first.activate();
    if (!s.ok()) throw std::runtime_error(s.message);
  }
  double offset_s = kNaN;  // session time = source time + offset
  double period_s = 1.0 / src->sample_rate_hz();
  double t_src_last = kNaN;
  Sample s;
  for (;;) {
    if (stop.load()) {
      stats_.complete = true;
      stats_.end_reason = "stopped by the user";
      break;
    }
    // switch-over: before the sample that would reach T, so T belongs to the second source
    if (want_switch && !stats_.switched && !std::isnan(t_last_) && t_last_ + period_s >= p_.switch_at_s - 1e-9) {
      const std::string from = src->name();
      drain(*src);
      src->deactivate();
      const Status st = second->activate();
      if (!st.ok()) {
        event("switch: to " + second->name() + " failed: " + st.message);
        stats_.end_reason = "switch-over failed: " + st.message;
        break;
      }
      src = second;
      select_motors(src);
      stats_.switched = true;
      const double next_period = 1.0 / src->sample_rate_hz();
      // the first sample of the new source lands one of its periods after the last row
      offset_s = kNaN;
      period_s = next_period;
      if (filter_) filter_->on_source_switch();
      event("switch: " + from + " -> " + src->name() + " (estimator state carried over; next row at t=" +
            [&] {
              char b[32];
              std::snprintf(b, sizeof b, "%.6f", t_last_ + next_period);
              return std::string(b);
            }() + " s)");
    }
    const ReadStatus st = src->read(s);
    drain(*src);
    if (st == ReadStatus::kPending || st == ReadStatus::kFault) continue;
    if (st == ReadStatus::kEnd) {
      stats_.complete = true;
      stats_.end_reason = src->name() + " ended";
      break;
    }
    if (st == ReadStatus::kFailed) {
      stats_.end_reason = src->name() + " failed: " + src->failure();
      break;
    }
    if (st == ReadStatus::kDisconnected) {
      if (!reconnect(*src, stop)) {
        stats_.complete = stop.load();
        stats_.end_reason = stop.load() ? "stopped by the user" : src->name() + " lost";
        break;
      }
      continue;
    }
    // one time line across sources: the first row is t = 0 s
    if (std::isnan(offset_s)) {
      offset_s = std::isnan(t_last_) ? -s.t_s : t_last_ + period_s - s.t_s;
    } else if (!(s.t_s > t_src_last)) {
      event("info: " + src->name() + ": sample at source time " + std::to_string(s.t_s) +
            " s does not follow " + std::to_string(t_src_last) + " s: dropped");
      continue;
    }
    t_src_last = s.t_s;
    s.t_s += offset_s;
    if (!std::isnan(t_last_) && s.t_s - t_last_ > 1.5 * period_s) {
      ++stats_.gaps;
      char b[160];
      std::snprintf(b, sizeof b, "gap: no samples between t=%.6f and t=%.6f s (%.0f periods missing)", t_last_,
                    s.t_s, std::round((s.t_s - t_last_) / period_s) - 1.0);
      event(b);
    }
    if (s.t_s >= p_.duration_s - 1e-9) {
      stats_.complete = true;
      stats_.end_reason = "duration reached";
      break;
    }
    if (motors_) {
      if (schedule_) {
        std::string fault;
        if (!schedule_->update(s.t_s, *motors_, &fault)) event("timeout: motors: " + fault);
      }
      if (!src->knows_platforms()) {
        s.plat1_deg = known_angle_deg(motors_->end_stop(1));
        s.plat2_deg = known_angle_deg(motors_->end_stop(2));
      }
    }
    if (pump_) pump_->write(s);
    const est::PushStatus pushed = filter_ ? filter_->push(s) : est::PushStatus::kInvalid;
    if (filter_) step_lock(pushed);
    t_last_ = s.t_s;
    if (fdi_ && filter_) {
      if (const std::string e = fdi_->push(s, pushed, *filter_); !e.empty()) event(e);
    }
    if (std::isnan(stats_.t_first_s)) stats_.t_first_s = s.t_s;
    stats_.t_last_s = s.t_s;
    ++stats_.samples;
    if (stats_.switched) {
      ++stats_.samples_second;
      if (std::isnan(stats_.t_switch_s)) stats_.t_switch_s = s.t_s;
    } else {
      ++stats_.samples_first;
    }
    if (on_sample_) on_sample_(s, *src);
  }
  drain(*src);
  src->deactivate();
  // the stream ended (whatever ended it): a standstill still open is good data, as at the end of a
  // log in 'estimate' (DriftlessFilter::finish), so the session and 'estimate' on its log agree
  if (filter_) step_lock(filter_->finish());
  return stats_;
}

}  // namespace driftless::hil
