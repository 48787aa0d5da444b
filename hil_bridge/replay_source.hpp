// Samples from a measurement log (docs/log-format.md), in real time or as fast as possible.
// The log's own event lines are passed on as events, so a replayed log keeps its marks.
#pragma once

#include <memory>
#include <string>

#include "estimator/log.hpp"
#include "hil_bridge/clock.hpp"
#include "hil_bridge/source.hpp"

namespace driftless::hil {

struct ReplayParams {
  std::string path;       // the log
  bool realtime = false;  // pace samples by their timestamps; false: as fast as possible
  double speed = 1.0;     // real-time factor when realtime (2 = twice as fast)
  void validate() const;
};

class ReplaySource final : public SampleSource {
 public:
  ReplaySource(Clock& clock, ReplayParams p);
  ~ReplaySource() override;
  std::string name() const override { return "replay:" + p_.path; }
  double sample_rate_hz() const override { return rate_hz_; }
  std::uint32_t fields() const override { return fields_; }
  void describe(log::Metadata& meta) const override;

  Status configure() override;
  Status activate() override;
  ReadStatus read(Sample& out) override;
  void deactivate() override;
  std::string failure() const override { return failure_; }

 private:
  Clock& clock_;
  ReplayParams p_;
  std::unique_ptr<log::LogReader> reader_;
  log::Metadata meta_;
  std::uint32_t fields_ = 0;
  double rate_hz_ = kNaN;
  double t_first_s_ = kNaN;
  double wall0_s_ = 0.0;
  std::size_t events_seen_ = 0;
  bool ended_ = false;
  std::string failure_;  // why read() returned kFailed
};

}  // namespace driftless::hil
