#include "hil_bridge/twin/twin_source.hpp"

#include <stdexcept>

namespace driftless::hil {

TwinSource::TwinSource(Clock& clock, twin::Scenario scenario, bool realtime)
    : clock_(clock), scenario_(std::move(scenario)), realtime_(realtime) {}

TwinSource::~TwinSource() = default;

void TwinSource::describe(log::Metadata& meta) const {
  const log::Metadata m = sim_ ? sim_->metadata() : twin::Simulator(scenario_).metadata();
  for (const auto& [k, v] : m.entries()) meta.set(k, v);
  meta.set("source", name());
}

Status TwinSource::configure() {
  try {
    sim_ = std::make_unique<twin::Simulator>(scenario_);
  } catch (const std::exception& e) {
    return Status::BadConfig(std::string("twin: ") + e.what());
  }
  return Status::Ok();
}

Status TwinSource::activate() {
  if (!sim_) return configure();
  wall0_s_ = clock_.now_s();
  return Status::Ok();
}

ReadStatus TwinSource::read(Sample& out) {
  if (!sim_) return ReadStatus::kEnd;
  if (!sim_->next(out)) return ReadStatus::kEnd;
  if (realtime_) clock_.sleep_until(wall0_s_ + out.t_s);
  return ReadStatus::kSample;
}

void TwinSource::deactivate() {}

Status TwinMotors::command(int, int) {
  return Status::BadConfig("twin motors: the scenario's flip_schedule drives the twin's servos");
}

EndStop TwinMotors::end_stop(int platform) const {
  const twin::Simulator* sim = src_.simulator();
  if (!sim || sim->flips().moving(platform)) return EndStop::kNone;
  return sim->flips().sign(platform) > 0 ? EndStop::kPlus : EndStop::kMinus;
}

namespace {
struct TwinRig final : SourceRig {
  SteadyClock clk;
  std::unique_ptr<TwinSource> src;
  std::unique_ptr<TwinMotors> tmotors;
};
}  // namespace

std::unique_ptr<SourceRig> make_twin_rig(const RigOptions& opt) {
  auto rig = std::make_unique<TwinRig>();
  twin::Scenario sc = opt.scenario.empty() ? twin::default_scenario() : twin::load_scenario(opt.scenario);
  rig->src = std::make_unique<TwinSource>(rig->clk, sc, opt.realtime);
  rig->tmotors = std::make_unique<TwinMotors>(*rig->src);
  rig->source = rig->src.get();
  // the twin knows its platform angles; its motors are reported but driven by the scenario
  rig->motors = nullptr;
  rig->clock = &rig->clk;
  rig->spec = "twin";
  return rig;
}

}  // namespace driftless::hil
