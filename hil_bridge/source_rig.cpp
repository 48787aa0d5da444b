#include "hil_bridge/source_rig.hpp"

#include <filesystem>
#include <stdexcept>

#include "estimator/log_metadata.hpp"
#include "hil_bridge/i2c/emulated_bus.hpp"
#include "hil_bridge/i2c/i2c_source.hpp"
#include "hil_bridge/i2c/linux_i2c.hpp"
#include "hil_bridge/replay_source.hpp"
#include "hil_bridge/serial/firmware_emulator.hpp"
#include "hil_bridge/serial/serial_source.hpp"
#include "hil_bridge/twin/sensor_model_generator.hpp"
#include "hil_bridge/twin/twin_source.hpp"

namespace driftless::hil {

const char* source_spec_help() {
  return "twin | replay:FILE | i2c:/dev/i2c-N | serial:/dev/ttyX | emu-i2c | emu-serial";
}

namespace {

bool starts_with(const std::string& s, const char* p) { return s.rfind(p, 0) == 0; }


struct ReplayRig final : SourceRig {
  std::unique_ptr<Clock> clk;
  std::unique_ptr<ReplaySource> src;
};

struct I2cRig final : SourceRig {
  SteadyClock clk;
  std::unique_ptr<LinuxI2c> bus;
  std::unique_ptr<I2cSource> src;
};

// an I2cSource that also names the emulated box's geometry in the metadata
class DescribedI2cSource final : public SampleSource {
 public:
  DescribedI2cSource(std::unique_ptr<I2cSource> inner, BoxAtRestGenerator::Params box, std::string name)
      : inner_(std::move(inner)), box_(std::move(box)), name_(std::move(name)) {}
  std::string name() const override { return name_; }
  double sample_rate_hz() const override { return inner_->sample_rate_hz(); }
  std::uint32_t fields() const override { return inner_->fields(); }
  bool knows_platforms() const override { return false; }
  void describe(log::Metadata& meta) const override {
    log::LogInfo info;
    info.latitude_deg = box_.latitude_deg;
    info.hinge1_axis = box_.hinge1_axis;
    info.hinge2_axis = box_.hinge2_axis;
    info.source = name_;
    log::write_log_info(meta, info);
  }
  Status configure() override { return inner_->configure(); }
  Status activate() override { return inner_->activate(); }
  ReadStatus read(Sample& out) override {
    const ReadStatus s = inner_->read(out);
    forward();
    return s;
  }
  Status reconnect() override {
    const Status s = inner_->reconnect();
    forward();
    return s;
  }
  void deactivate() override { inner_->deactivate(); }

 private:
  void forward() {
    if (!inner_->has_events()) return;
    std::vector<SourceEvent> ev;
    inner_->take_events(ev);
    for (auto& e : ev) report(e.kind, e.t_s, std::move(e.text), e.lost_samples);
  }
  std::unique_ptr<I2cSource> inner_;
  BoxAtRestGenerator::Params box_;
  std::string name_;
};

struct EmuI2cRig final : SourceRig {
  std::unique_ptr<Clock> clk;
  VirtualClock* vclk = nullptr;
  std::unique_ptr<EmulatedMotors> emotors;
  std::unique_ptr<ImuGenerator> gen;
  std::unique_ptr<Mpu6050Emulator> chip1, chip2;
  std::unique_ptr<EmulatedI2cBus> bus;
  std::unique_ptr<DescribedI2cSource> src;
  std::unique_ptr<FlipSchedule> sched;
};

struct SerialRig final : SourceRig {
  SteadyClock clk;
  std::unique_ptr<FirmwareEmulator> firmware;  // emu-serial only
  std::unique_ptr<SerialSource> src;
  std::unique_ptr<SerialMotors> smotors;
  std::unique_ptr<FlipSchedule> sched;
  std::string start() override { return firmware ? firmware->start() : std::string(); }
};

// what the emulated chips measure: the built-in box at rest, or the twin's sensor model preset
// named by --emu-sensor (the same box, latitude and motors); with --emu-fault, a planted fault
std::unique_ptr<ImuGenerator> make_generator(const RigOptions& opt, const BoxAtRestGenerator::Params& gp,
                                             const EmulatedMotors* motors) {
  std::unique_ptr<ImuGenerator> gen;
  if (opt.emu_sensor.empty()) {
    gen = std::make_unique<BoxAtRestGenerator>(gp, motors);
  } else {
    const twin::SensorParams sp = twin::sensor_preset(opt.emu_sensor);
    gen = std::make_unique<SensorModelGenerator>(sp, sp, opt.sample_rate_hz, opt.seed, gp, motors);
  }
  if (!opt.emu_fault.planted()) return gen;
  return std::make_unique<FaultyGenerator>(std::move(gen), opt.emu_fault);
}

}  // namespace

std::unique_ptr<SourceRig> make_source_rig(const std::string& spec, const RigOptions& opt) {
  FlipSchedule::Params flip;
  flip.standstill_s = opt.standstill_s;
  if (starts_with(spec, "replay:")) {
    auto rig = std::make_unique<ReplayRig>();
    rig->clk = std::make_unique<SteadyClock>();
    ReplayParams rp;
    rp.path = spec.substr(7);
    rp.realtime = opt.realtime;
    rig->src = std::make_unique<ReplaySource>(*rig->clk, rp);
    rig->source = rig->src.get();
    rig->clock = rig->clk.get();
    rig->spec = spec;
    return rig;
  }
  if (starts_with(spec, "i2c:")) {
    auto rig = std::make_unique<I2cRig>();
    rig->bus = std::make_unique<LinuxI2c>(spec.substr(4));
    I2cSourceParams ip;
    ip.sample_rate_hz = opt.sample_rate_hz;
    rig->src = std::make_unique<I2cSource>(*rig->bus, rig->clk, ip);
    rig->source = rig->src.get();
    rig->clock = &rig->clk;
    rig->spec = spec;
    return rig;
  }
  if (spec == "emu-i2c") {
    auto rig = std::make_unique<EmuI2cRig>();
    if (opt.realtime) {
      rig->clk = std::make_unique<SteadyClock>();
    } else {
      auto v = std::make_unique<VirtualClock>();
      rig->vclk = v.get();
      rig->clk = std::move(v);
    }
    rig->emotors = std::make_unique<EmulatedMotors>(*rig->clk, EmulatedMotors::Params{});
    BoxAtRestGenerator::Params gp = opt.emulated_box;
    gp.sample_rate_hz = opt.sample_rate_hz;
    gp.seed = opt.seed;
    rig->gen = make_generator(opt, gp, rig->emotors.get());
    rig->chip1 = std::make_unique<Mpu6050Emulator>(0, *rig->gen, *rig->clk);
    rig->chip2 = std::make_unique<Mpu6050Emulator>(1, *rig->gen, *rig->clk);
    rig->bus = std::make_unique<EmulatedI2cBus>(*rig->clk, rig->vclk);
    rig->bus->attach(0x68, rig->chip1.get());
    rig->bus->attach(0x69, rig->chip2.get());
    I2cSourceParams ip;
    ip.sample_rate_hz = opt.sample_rate_hz;
    rig->src = std::make_unique<DescribedI2cSource>(std::make_unique<I2cSource>(*rig->bus, *rig->clk, ip), gp,
                                                    "emu-i2c");
    rig->sched = std::make_unique<FlipSchedule>(flip);
    rig->source = rig->src.get();
    rig->motors = rig->emotors.get();
    rig->schedule = rig->sched.get();
    rig->clock = rig->clk.get();
    rig->spec = spec;
    return rig;
  }
  if (starts_with(spec, "serial:") || spec == "emu-serial") {
    auto rig = std::make_unique<SerialRig>();
    SerialSourceParams sp;
    sp.baud = opt.baud;
    sp.sample_rate_hz = opt.sample_rate_hz;
    if (spec == "emu-serial") {
      FirmwareParams fp;
      fp.link_path = (std::filesystem::path(opt.work_dir) / "emu-serial.tty").string();
      fp.rate_hz = opt.sample_rate_hz;
      fp.generator = opt.emulated_box;
      fp.generator.seed = opt.seed;
      if (!opt.emu_sensor.empty() || opt.emu_fault.planted()) {
        make_generator(opt, fp.generator, nullptr);  // an unknown preset fails here, before the run
        fp.make_generator = [opt, gp = fp.generator](const EmulatedMotors* motors, double rate_hz) {
          BoxAtRestGenerator::Params g = gp;
          g.sample_rate_hz = rate_hz;
          RigOptions o = opt;
          o.sample_rate_hz = rate_hz;
          return make_generator(o, g, motors);
        };
      }
      // the emulated microcontroller streams in real time: a pty has no "as fast as possible"
      rig->firmware = std::make_unique<FirmwareEmulator>(fp);
      sp.path = fp.link_path;
    } else {
      sp.path = spec.substr(7);
    }
    rig->src = std::make_unique<SerialSource>(rig->clk, sp);
    rig->smotors = std::make_unique<SerialMotors>(*rig->src);
    rig->sched = std::make_unique<FlipSchedule>(flip);
    rig->source = rig->src.get();
    rig->motors = rig->smotors.get();
    rig->schedule = rig->sched.get();
    rig->clock = &rig->clk;
    rig->spec = spec;
    return rig;
  }
  if (spec == "twin") {
    return make_twin_rig(opt);
  }
  throw std::invalid_argument("hil: unknown source '" + spec + "' (expected " + source_spec_help() + ")");
}

}  // namespace driftless::hil
