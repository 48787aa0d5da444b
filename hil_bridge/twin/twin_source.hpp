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
  /// `realtime`: pace samples by the wall clock of `clock`.
  TwinSource(Clock& clock, twin::Scenario scenario, bool realtime);
  ~TwinSource() override;
  std::string name() const override { return "twin:" + scenario_.name; }
  double sample_rate_hz() const override { return scenario_.sample_rate_hz; }
  std::uint32_t fields() const override { return twin::Simulator::fields(); }
  void describe(log::Metadata& meta) const override;

  Status configure() override;
  Status activate() override;
  ReadStatus read(Sample& out) override;
  void deactivate() override;

  /// The running simulator (null before activate()).
  const twin::Simulator* simulator() const { return sim_.get(); }

 private:
  Clock& clock_;
  twin::Scenario scenario_;
  bool realtime_;
  std::unique_ptr<twin::Simulator> sim_;
  double wall0_s_ = 0.0;
};

/// The twin's MuJoCo platform servos as motors. The scenario's flip schedule drives them inside
/// the simulator, so command() is refused; end_stop() reports the platform at its commanded rest
/// angle once settled (what end-stop switches would say).
class TwinMotors final : public Motors {
 public:
  explicit TwinMotors(const TwinSource& src) : src_(src) {}
  std::string name() const override { return "twin"; }
  Status command(int platform, int sign) override;
  EndStop end_stop(int platform) const override;

 private:
  const TwinSource& src_;
};

/// The `twin` source rig (scenario from RigOptions::scenario, or the built-in default).
std::unique_ptr<SourceRig> make_twin_rig(const RigOptions& opt);

}  // namespace driftless::hil
