// The twin as a sample source: twin::Simulator stepped to the next output sample, in real time
// or as fast as possible; and the twin's actuators seen as a Motors back end.
#pragma once

#include <memory>
#include <string>

#include "hil_bridge/clock.hpp"
#include "hil_bridge/motors.hpp"
#include "hil_bridge/source.hpp"
#include "hil_bridge/source_rig.hpp"
#include "twin/scenario.hpp"
#include "twin/simulator.hpp"

namespace driftless::hil {

class TwinSource final : public SampleSource {
 public:
  /// `realtime`: pace samples by the wall clock of `clock`. `bridge_flips`: the bridge drives the
  /// platform servos (TwinMotors::command) instead of the scenario's flip schedule.
  TwinSource(Clock& clock, twin::Scenario scenario, bool realtime, bool bridge_flips = false);
  ~TwinSource() override;
  std::string name() const override { return "twin:" + scenario_.name; }
  double sample_rate_hz() const override { return scenario_.sample_rate_hz; }
  std::uint32_t fields() const override { return twin::Simulator::fields(); }
  void describe(log::Metadata& meta) const override;

  Status configure() override;
  Status activate() override;
  ReadStatus read(Sample& out) override;
  void deactivate() override;

  /// The running simulator (null before configure()).
  const twin::Simulator* simulator() const { return sim_.get(); }
  /// True when the bridge, not the scenario, commands the platform servos.
  bool bridge_flips() const { return bridge_flips_; }
  /// Starts platform `platform` (1 or 2) toward its stop of sign `sign` (-1 or +1) in the
  /// simulation; refused (BadConfig) unless bridge_flips, or before configure().
  Status command_platform(int platform, int sign);

 private:
  Clock& clock_;
  twin::Scenario scenario_;
  bool realtime_;
  bool bridge_flips_;
  std::unique_ptr<twin::Simulator> sim_;
  double wall0_s_ = 0.0;
};

/// The twin's MuJoCo platform servos as motors. With a source made with bridge_flips, command()
/// starts a flip that the simulated servo executes (speed/acceleration limits, end stops, settling);
/// otherwise the scenario's flip schedule drives them and command() is refused. end_stop()
/// reports the platform at its commanded rest angle once settled (what end-stop switches say).
class TwinMotors final : public Motors {
 public:
  explicit TwinMotors(TwinSource& src) : src_(src) {}
  std::string name() const override { return "twin"; }
  Status command(int platform, int sign) override;
  EndStop end_stop(int platform) const override;

 private:
  TwinSource& src_;
};

/// The `twin` source rig (scenario from RigOptions::scenario, or the built-in default). With
/// RigOptions::twin_bridge_flips the rig's FlipSchedule drives the twin's servos through TwinMotors.
std::unique_ptr<SourceRig> make_twin_rig(const RigOptions& opt);

}  // namespace driftless::hil
