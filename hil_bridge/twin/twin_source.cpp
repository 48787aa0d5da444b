#include "hil_bridge/twin/twin_source.hpp"

#include <stdexcept>
#include <string>

namespace driftless::hil {

TwinSource::TwinSource(Clock& clock, twin::Scenario scenario, bool realtime, bool bridge_flips)
    : clock_(clock), scenario_(std::move(scenario)), realtime_(realtime), bridge_flips_(bridge_flips) {}

TwinSource::~TwinSource() = default;

void TwinSource::describe(log::Metadata& meta) const {
  const log::Metadata m = sim_ ? sim_->metadata() : twin::Simulator(scenario_).metadata();
  for (const auto& [k, v] : m.entries()) meta.set(k, v);
  meta.set("source", name());
  if (bridge_flips_) meta.set("flip_control", "bridge");
}

Status TwinSource::configure() {
  try {
    sim_ = std::make_unique<twin::Simulator>(scenario_);
    if (bridge_flips_) sim_->take_flip_control();
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

Status TwinSource::command_platform(int platform, int sign) {
  if (!bridge_flips_) {
    return Status::BadConfig("twin motors: the scenario's flip_schedule drives the twin's servos "
                             "(run the twin with bridge-driven flips: --twin-flips bridge)");
  }
  if (!sim_) return Status::BadConfig("twin motors: the twin source is not configured");
  if ((platform != 1 && platform != 2) || (sign != 1 && sign != -1)) {
    return Status::BadConfig("twin motors: expected platform 1 or 2 and sign +1 or -1, got " +
                             std::to_string(platform) + ", " + std::to_string(sign));
  }
  sim_->command_platform(platform, sign);
  return Status::Ok();
}

Status TwinMotors::command(int platform, int sign) { return src_.command_platform(platform, sign); }

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
  std::unique_ptr<FlipSchedule> sched;
};
}  // namespace

std::unique_ptr<SourceRig> make_twin_rig(const RigOptions& opt) {
  auto rig = std::make_unique<TwinRig>();
  twin::Scenario sc = opt.scenario.empty() ? twin::default_scenario() : twin::load_scenario(opt.scenario);
  rig->src = std::make_unique<TwinSource>(rig->clk, sc, opt.realtime, opt.twin_bridge_flips);
  rig->tmotors = std::make_unique<TwinMotors>(*rig->src);
  rig->source = rig->src.get();
  // bridge-driven flips: the bridge's flip schedule commands the twin's servos, as it commands
  // the real box's motors; otherwise the scenario's schedule runs inside the simulator
  if (opt.twin_bridge_flips) {
    FlipSchedule::Params fp;
    fp.standstill_s = opt.standstill_s;
    rig->sched = std::make_unique<FlipSchedule>(fp);
    rig->motors = rig->tmotors.get();
    rig->schedule = rig->sched.get();
  }
  rig->clock = &rig->clk;
  rig->spec = "twin";
  return rig;
}

}  // namespace driftless::hil
