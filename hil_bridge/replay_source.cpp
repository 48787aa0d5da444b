#include "hil_bridge/replay_source.hpp"

#include <cmath>
#include <filesystem>
#include <stdexcept>

namespace driftless::hil {

void ReplayParams::validate() const {
  if (path.empty()) throw std::invalid_argument("replay: no log given (replay:FILE)");
  if (!(speed > 0.0)) throw std::invalid_argument("replay: speed must be > 0");
}

ReplaySource::ReplaySource(Clock& clock, ReplayParams p) : clock_(clock), p_(std::move(p)) {}
ReplaySource::~ReplaySource() = default;

void ReplaySource::describe(log::Metadata& meta) const {
  // the box and sensors are the recording's: keep its geometry, place, rest angles and gyro range
  // (the session's filter takes its geometry from these keys, the log's readers the range)
  // (a sensor's own range, gyro1_/gyro2_full_scale_dps, overrides the shared one: without it the
  // session's log would refuse the wider gyro's good readings or hide the narrower one's clipping)
  for (const char* key : {"latitude_deg", "hinge1_axis", "hinge2_axis", "flip_angle_deg", "end_stop_deg",
                          "gyro_full_scale_dps", "gyro1_full_scale_dps", "gyro2_full_scale_dps",
                          "platform_readback", "sensor1_preset", "sensor2_preset"}) {
    if (auto v = meta_.get(key)) meta.set(key, *v);
  }
  meta.set("source", name());
}

Status ReplaySource::configure() {
  try {
    p_.validate();
  } catch (const std::invalid_argument& e) {
    return Status::BadConfig(e.what());
  }
  if (!std::filesystem::exists(p_.path)) return Status::NotFound("replay: " + p_.path + ": no such file");
  try {
    reader_ = std::make_unique<log::LogReader>(p_.path);
  } catch (const std::exception& e) {
    return Status::BadConfig(e.what());
  }
  meta_ = reader_->metadata();
  fields_ = reader_->fields();
  rate_hz_ = meta_.get_number("sample_rate_hz", kNaN);
  if (!(rate_hz_ > 0.0)) {
    // the session's period, gap detection and the filter's noise per sample need the rate
    return Status::BadConfig("replay: " + p_.path + " has no sample_rate_hz in its metadata: add a line "
                             "'# sample_rate_hz: <Hz>' before its header row (docs/log-format.md)");
  }
  return Status::Ok();
}

Status ReplaySource::activate() {
  if (!reader_) return Status::BadConfig("replay: configure() first");
  wall0_s_ = clock_.now_s();
  return Status::Ok();
}

void ReplaySource::deactivate() { ended_ = true; }

ReadStatus ReplaySource::read(Sample& out) {
  if (ended_ || !reader_) return ReadStatus::kEnd;
  bool got = false;
  try {
    got = reader_->next(out);
  } catch (const std::exception& e) {
    // a malformed row ends the replay; the rows before it stand, and the session says it is
    // incomplete (the recording was not replayed to its end)
    failure_ = std::string("replay stopped: ") + e.what();
    report(EventKind::kCorruptFrame, kNaN, failure_);
    ended_ = true;
    return ReadStatus::kFailed;
  }
  // the recording's own event lines
  const auto& ev = reader_->events();
  for (; events_seen_ < ev.size(); ++events_seen_) {
    report(EventKind::kInfo, ev[events_seen_].t_s, "replayed event: " + ev[events_seen_].text);
  }
  if (!got) {
    ended_ = true;
    return ReadStatus::kEnd;
  }
  if (std::isnan(t_first_s_)) t_first_s_ = out.t_s;
  if (p_.realtime) clock_.sleep_until(wall0_s_ + (out.t_s - t_first_s_) / p_.speed);
  return ReadStatus::kSample;
}

}  // namespace driftless::hil
