// driftless hil: run the estimator live on a source of samples (the twin, a replayed log, two
// MPU-6050s on I2C, the box's microcontroller on a serial link, or their emulators), record a
// measurement log, and optionally switch sources mid-run without restarting the estimator.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include <fmt/core.h>

#include "cli/command.hpp"
#include "cli/hil_fdi.hpp"
#include "estimator/filter.hpp"
#include "estimator/health.hpp"
#include "estimator/log.hpp"
#include "estimator/log_metadata.hpp"
#include "hil_bridge/cpu_latency.hpp"
#include "hil_bridge/live_loop.hpp"
#include "hil_bridge/source_rig.hpp"

namespace driftless::cli {
namespace {

struct HilOptions {
  std::string source, switch_to, out_dir, estimator_config, scenario, emu_sensor, emu_fault;
  std::string twin_flips = "scenario";
  double at_s = kNaN;
  double duration_s = kNaN;
  double rate_hz = 100.0;
  double standstill_s = 10.0;
  double print_every_s = 10.0;
  int baud = 921600;
  std::uint64_t seed = 1;
  bool realtime = false;
  bool fdi = false;
  bool allow_deep_idle = false;
};

std::string vec3(const Eigen::Vector3d& v) { return fmt::format("{:+.4f} {:+.4f} {:+.4f}", v.x(), v.y(), v.z()); }

// A session paced by the wall clock (hardware, emu-serial, --realtime) polls its source on time;
// ask Linux to keep the cores out of deep idle states while it runs (docs/hil.md "Speed").
std::unique_ptr<hil::CpuLatencyRequest> hold_cpus_awake(const HilOptions& o, const hil::SourceRig& first,
                                                        const hil::SourceRig* second) {
  auto paced = [](const hil::SourceRig& r) { return dynamic_cast<const hil::SteadyClock*>(r.clock) != nullptr; };
  if (o.allow_deep_idle || !(paced(first) || (second && paced(*second)))) return nullptr;
  auto req = std::make_unique<hil::CpuLatencyRequest>(0);
  if (req->held()) {
    fmt::print("driftless hil: holding the CPUs out of deep idle states while the session runs (PM QoS 0 us; "
               "--allow-deep-idle to save power)\n");
  } else {
    fmt::print(stderr, "driftless hil: note: could not keep the CPUs out of deep idle states ({}): wake-up "
               "latency may add tens of microseconds on an idle machine\n", req->why_not());
  }
  return req;
}

// what the source rigs need of the options; refuses combinations that cannot work
hil::RigOptions rig_options(const HilOptions& o) {
  hil::RigOptions ro;
  ro.realtime = o.realtime;
  ro.sample_rate_hz = o.rate_hz;
  ro.standstill_s = o.standstill_s;
  ro.baud = o.baud;
  ro.work_dir = o.out_dir;
  ro.seed = o.seed;
  ro.scenario = o.scenario;
  ro.emu_sensor = o.emu_sensor;
  if (o.twin_flips != "scenario" && o.twin_flips != "bridge") {
    throw std::invalid_argument("hil: --twin-flips: expected scenario or bridge, got '" + o.twin_flips + "'");
  }
  ro.twin_bridge_flips = o.twin_flips == "bridge";
  if (ro.twin_bridge_flips && o.source != "twin" && o.switch_to != "twin") {
    throw std::invalid_argument("hil: --twin-flips bridge needs the twin source (--source twin or --switch-to twin)");
  }
  if (!o.emu_fault.empty()) {
    const auto emulated = [](const std::string& s) { return s == "emu-i2c" || s == "emu-serial"; };
    if (!emulated(o.source) && !emulated(o.switch_to)) {
      throw std::invalid_argument("hil: --emu-fault plants a fault into the emulated chips: it needs --source (or "
                                  "--switch-to) emu-i2c or emu-serial");
    }
    ro.emu_fault = hil::parse_planted_fault(o.emu_fault);
  }
  return ro;
}

// the source options, and the kinds of source each one sets something of
struct SourceOption {
  const char* name;
  bool (*applies)(const std::string& spec, const HilOptions& o);
  const char* sources;  // for the message
};

bool starts_with(const std::string& s, const char* p) { return s.rfind(p, 0) == 0; }
bool is_device(const std::string& s) { return starts_with(s, "i2c:") || starts_with(s, "serial:"); }
bool is_emulator(const std::string& s) { return s == "emu-i2c" || s == "emu-serial"; }
bool is_serial(const std::string& s) { return starts_with(s, "serial:") || s == "emu-serial"; }

constexpr SourceOption kSourceOptions[] = {
    {"--rate", [](const std::string& s, const HilOptions&) { return is_device(s) || is_emulator(s); },
     "i2c:, serial:, emu-i2c and emu-serial (a replay runs at its log's rate, the twin at its scenario's)"},
    {"--baud", [](const std::string& s, const HilOptions&) { return is_serial(s); }, "serial: and emu-serial"},
    {"--scenario", [](const std::string& s, const HilOptions&) { return s == "twin"; }, "twin"},
    {"--emu-sensor", [](const std::string& s, const HilOptions&) { return is_emulator(s); }, "emu-i2c and emu-serial"},
    {"--seed", [](const std::string& s, const HilOptions&) { return is_emulator(s) || s == "twin"; },
     "emu-i2c, emu-serial and twin"},
    {"--standstill",
     [](const std::string& s, const HilOptions& o) {
       return is_device(s) || is_emulator(s) || (s == "twin" && o.twin_flips == "bridge");
     },
     "i2c:, serial:, emu-i2c, emu-serial and twin with --twin-flips bridge (the bridge's flip schedule; a "
     "replay's platforms flip as recorded)"},
};

// an option given for a source that does not use it would be ignored without a word: refused
// (a usage error), e.g. --rate 1000 with a replay of a 10 Hz log
void refuse_options_no_source_uses(const CLI::App& cmd, const HilOptions& o) {
  for (const SourceOption& opt : kSourceOptions) {
    if (cmd.count(opt.name) == 0) continue;
    if (opt.applies(o.source, o) || (!o.switch_to.empty() && opt.applies(o.switch_to, o))) continue;
    throw CLI::ValidationError(opt.name, fmt::format("{} is for {}; the session's source{} ({}{}) would ignore it: "
                                                     "leave it out",
                                                     opt.name, opt.sources, o.switch_to.empty() ? "" : "s", o.source,
                                                     o.switch_to.empty() ? "" : ", " + o.switch_to));
  }
  if (!std::isnan(o.at_s) && !std::isnan(o.duration_s) && !(o.at_s < o.duration_s)) {
    throw CLI::ValidationError("--at", fmt::format("the switch at {:g} s would come after the session's end at "
                                                   "--duration {:g} s", o.at_s, o.duration_s));
  }
}

// the bias lines are the filter's start value until it locked (estimate's lock level, with its
// hysteresis: LiveStats steps it at each update as 'estimate' does): say so when it never locked
// or lost the lock by the end, and why when the samples never had both triads
void warn_about_lock(const est::DriftlessFilter& filter, const hil::LiveStats& st) {
  if (st.locked_at_end) return;
  const double lock_dps = est::HealthLimits{}.lock_sigma_dps;
  const double sigma_dps = filter.correction_sigma_dps().maxCoeff();
  const est::FilterCounters& c = filter.counters();
  const std::string invalid =
      c.invalid > 0 ? fmt::format("; {} of {} samples lacked a gyro value (an empty column: a dead axis or "
                                  "a missing sensor?)", c.invalid, c.samples)
                    : "";
  if (st.ever_locked) {
    fmt::print(stderr,
               "driftless hil: warning: the filter lost its lock before the end (largest sigma {:.3g} deg/s; it "
               "locks below {:g} and loses the lock above {:g} or at a gate re-lock; {} update(s), {} rejected, {} "
               "re-lock(s)): the biases above are not estimates{}\n",
               sigma_dps, lock_dps, est::kUnlockFactor * lock_dps, c.updates, c.rejected, c.relocks, invalid);
    return;
  }
  fmt::print(stderr,
             "driftless hil: warning: the filter never locked (largest sigma {:.3g} deg/s, locked below {:g}; {} "
             "update(s), {} rejected): the biases above are not estimates{}\n",
             sigma_dps, lock_dps, c.updates, c.rejected, invalid);
}

// The log states one sample_rate_hz and the estimator's noise per sample (R) is set from it, so a
// switch to a source of another rate would write rows that the log's own metadata misdescribes and
// feed the filter with a wrong R. Refused before anything runs.
void refuse_switch_between_rates(const hil::SampleSource& a, const hil::SampleSource& b) {
  const double fa = a.sample_rate_hz();
  const double fb = b.sample_rate_hz();
  if (std::abs(fa - fb) <= 1e-9 * std::max(fa, fb)) return;
  throw std::invalid_argument(fmt::format(
      "hil: --switch-to {} samples at {:g} Hz but --source {} at {:g} Hz: one log states one sample_rate_hz and "
      "the estimator's noise per sample follows it; switch between sources of one rate (--rate sets the emulated "
      "and twin sources' rate; a replayed log keeps its own)",
      b.name(), fb, a.name(), fa));
}

int run_hil(const HilOptions& o) {
  std::filesystem::create_directories(o.out_dir);

  const hil::RigOptions ro = rig_options(o);
  auto first = hil::make_source_rig(o.source, ro);
  std::unique_ptr<hil::SourceRig> second;
  if (!o.switch_to.empty()) second = hil::make_source_rig(o.switch_to, ro);
  const bool hardware = o.source.rfind("i2c:", 0) == 0 || o.source.rfind("serial:", 0) == 0 ||
                        o.source == "emu-serial";
  if (std::isnan(o.duration_s) && !hardware && o.source.rfind("replay:", 0) != 0 && o.source != "twin") {
    throw std::invalid_argument("hil: " + o.source + " streams forever: give --duration S (s)");
  }

  // every device is checked before anything runs: a missing one is one clear error
  for (hil::SourceRig* rig : {first.get(), second.get()}) {
    if (!rig) continue;
    if (std::string err = rig->start(); !err.empty()) throw std::runtime_error(err);
    const hil::Status s = rig->source->configure();
    if (!s.ok()) throw std::runtime_error(s.message);
  }
  if (second) refuse_switch_between_rates(*first->source, *second->source);

  log::Metadata meta;
  log::LogInfo info;
  info.sample_rate_hz = first->source->sample_rate_hz();
  info.latitude_deg = 52.0;  // deg, the paper's lab; a source that knows its box overrides it
  log::write_log_info(meta, info);
  first->source->describe(meta);
  if (second) {
    meta.set("switch_to", second->source->name());
    log::set_number(meta, "switch_at_s", o.at_s);
  }
  if (ro.emu_fault.planted()) meta.set("emu_fault", ro.emu_fault.describe());
  std::uint32_t fields = first->source->fields() | (second ? second->source->fields() : 0u);

  est::EstimatorConfig cfg;
  if (!o.estimator_config.empty()) {
    std::ifstream in(o.estimator_config);
    if (!in) throw std::runtime_error(o.estimator_config + ": cannot open the estimator configuration");
    cfg = est::parse_estimator_config(in, o.estimator_config, cfg);
  }
  est::DriftlessFilter filter(cfg, est::box_geometry_from_metadata(meta));

  const std::filesystem::path log_path = std::filesystem::path(o.out_dir) / "log.csv";
  log::LogWriter writer(log_path, meta, fields);

  hil::LiveParams lp;
  if (!std::isnan(o.duration_s)) lp.duration_s = o.duration_s;
  lp.switch_at_s = o.at_s;
  hil::SteadyClock wall;
  const auto latency_request = hold_cpus_awake(o, *first, second.get());
  hil::LiveLoop loop(lp, wall, &writer, &filter);
  std::unique_ptr<hil::FdiWatch> fdi;
  if (o.fdi) {
    est::FdiParams fp;
    fp.sample_rate_hz = info.sample_rate_hz;
    fdi = std::make_unique<hil::FdiWatch>(fp, cfg.end_margin_s);
    loop.set_fdi(fdi.get());
  }
  loop.set_motors(first->source, first->motors, first->schedule);
  if (second) loop.set_motors(second->source, second->motors, second->schedule);
  // the terminal view: bias estimates as they converge
  double next_print = 0.0;
  std::uint64_t updates_seen = 0;
  fmt::print("driftless hil: {} -> {}{}\n", first->source->name(), log_path.string(),
             second ? fmt::format(" (switch to {} at t={} s)", second->source->name(), o.at_s) : "");
  fmt::print("{:>10}  {:<29}  {:<29}  {:>7}  {}\n", "t [s]", "b1 [deg/s] (x y z)", "b2 [deg/s] (x y z)", "updates",
             "source");
  loop.on_sample([&](const Sample& s, hil::SampleSource& src) {
    const bool new_update = filter.counters().updates != updates_seen;
    updates_seen = filter.counters().updates;
    if (s.t_s >= next_print || (o.realtime && new_update)) {
      fmt::print("{:>10.2f}  {:<29}  {:<29}  {:>7}  {}\n", s.t_s, vec3(filter.bias1_dps()), vec3(filter.bias2_dps()),
                 filter.counters().updates, src.name());
      std::fflush(stdout);
      next_print = std::floor(s.t_s / o.print_every_s + 1.0) * o.print_every_s;
    }
  });
  loop.on_event([&](double t, const std::string& text) { fmt::print("{:>10.2f}  event: {}\n", t, text); });

  hil::LiveStats st;
  try {
    st = loop.run(*first->source, second ? second->source : nullptr, stop_requested());
  } catch (const std::exception& e) {
    // whatever broke mid-run (a disk that filled, a source that threw), the rows so far stay a
    // valid log that says it is incomplete and why
    try {
      writer.finish(false, std::string("hil stopped by an error: ") + e.what());
    } catch (...) {
    }
    throw;
  }
  const bool switch_missed = second && !st.switched && st.complete;
  if (switch_missed) {
    writer.event(st.t_last_s, fmt::format("switch: to {} at t={:g} s did not happen: {}", second->source->name(),
                                          o.at_s, st.end_reason));
  }
  writer.finish(st.complete, st.end_reason);

  const Eigen::Matrix<double, 6, 1> sig = filter.sigma_dps();
  fmt::print("done: {} ({} rows, t = {:.3f} .. {:.3f} s, {} events, {} faults, {} samples reported lost, {} gaps{})\n",
             st.end_reason, st.samples, st.t_first_s, st.t_last_s, st.events, st.faults, st.lost_samples, st.gaps,
             st.switched ? fmt::format(", switched at t={:.6f} s", st.t_switch_s) : "");
  fmt::print("bias 1 [deg/s]: {}  sigma {}\n", vec3(filter.bias1_dps()), vec3(sig.head<3>()));
  fmt::print("bias 2 [deg/s]: {}  sigma {}\n", vec3(filter.bias2_dps()), vec3(sig.tail<3>()));
  fmt::print("filter: {} updates, {} rejected by the NIS gate, {} source switches\n", filter.counters().updates,
             filter.counters().rejected, filter.counters().source_switches);
  fmt::print("log: {}\n", log_path.string());
  warn_about_lock(filter, st);
  if (!st.complete) throw std::runtime_error("hil: " + st.end_reason + "; the log so far is " + log_path.string() +
                                             " (complete: false)");
  if (switch_missed) {
    // the session asked for did not run: the log holds the first source only
    throw std::runtime_error(fmt::format("hil: the switch to {} at t={:g} s did not happen: {} at t={:.3f} s; {} holds "
                                         "{} only (give an --at inside the first source's span)",
                                         second->source->name(), o.at_s, st.end_reason, st.t_last_s,
                                         log_path.string(), first->source->name()));
  }
  if (!fdi) return 0;
  const std::filesystem::path fdi_json = std::filesystem::path(o.out_dir) / "fdi.json";
  write_fdi_json(fdi_json, *fdi);
  return report_fdi(*fdi, fdi_json);
}

const bool registered_hil = register_command(60, [](CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "hil", "Run the estimator live on the twin, a replayed log, MPU-6050s on I2C, the box's serial link or "
             "their emulators; record a measurement log; switch sources mid-run (docs/hil.md)");
  auto o = std::make_shared<HilOptions>();
  cmd->add_option("--source", o->source, std::string("Source of samples: ") + hil::source_spec_help())->required();
  auto* switch_to = cmd->add_option("--switch-to", o->switch_to, "Second source, taken over at --at (same spellings)");
  auto* at = cmd->add_option("--at", o->at_s, "Session time of the switch-over, s")->check(positive_number("s"));
  switch_to->needs(at);
  at->needs(switch_to);
  cmd->add_option("--out", o->out_dir, "Output directory (log.csv is written there)")->required();
  cmd->add_flag("--realtime", o->realtime,
                "Pace the twin, replays and emu-i2c by the wall clock (default: as fast as possible; "
                "hardware and emu-serial always run in real time)");
  cmd->add_flag("--allow-deep-idle", o->allow_deep_idle,
                "Do not ask Linux to keep the CPUs out of deep idle states during a session paced by the wall "
                "clock (saves power; wake-ups can then be tens of microseconds later)");
  cmd->add_option("--duration", o->duration_s, "Session time to run, s (default: until the source ends)")
      ->check(positive_number("s"));
  cmd->add_option("--rate", o->rate_hz, "Sample rate of i2c, serial and emulated sources, Hz")
      ->check(positive_number("Hz"))
      ->default_val(100.0);
  cmd->add_option("--standstill", o->standstill_s, "Flip schedule hold time at each position, s")
      ->check(positive_number("s"))
      ->default_val(10.0);
  cmd->add_option("--baud", o->baud, "Serial link speed, bit/s")->default_val(921600);
  cmd->add_option("--scenario", o->scenario, "twin: scenario YAML file or built-in name (default: the built-in default)");
  cmd->add_option("--emu-sensor", o->emu_sensor,
                  "emu-i2c, emu-serial: drive the emulated chips with the twin's sensor model preset "
                  "(mpu6050, ideal) instead of the built-in biases + white noise");
  cmd->add_option("--emu-fault", o->emu_fault,
                  "emu-i2c, emu-serial: plant a sensor fault in the emulated chips: stuck:S:A@T (axis A of sensor S "
                  "sticks at its value from source time T s) or bias:S:A:DPS@T (adds DPS deg/s); S 1|2, A x|y|z");
  cmd->add_flag("--fdi", o->fdi,
                "Run fault detection beside the estimator (docs/fdi.md): 'fdi:' event lines, DIR/fdi.json, and "
                "exit 1 when a sensor fault is detected or the run was too short to monitor");
  cmd->add_option("--twin-flips", o->twin_flips,
                  "twin: who flips the platforms: scenario (its flip_schedule, inside the simulator) or "
                  "bridge (the bridge's flip schedule commands the twin's servos, --standstill s hold)")
      ->default_val("scenario");
  cmd->add_option("--seed", o->seed, "Seed of the emulators and the twin, 0 .. 2^64-1")
      ->check(seed_number())
      ->default_val(1);
  cmd->add_option("--estimator-config", o->estimator_config, "Estimator configuration (key: value, docs/estimator.md)");
  cmd->add_option("--print-every", o->print_every_s, "Terminal line every this much session time, s")
      ->check(positive_number("s"))
      ->default_val(10.0);
  cmd->parse_complete_callback([cmd, o] { refuse_options_no_source_uses(*cmd, *o); });
  return [o] { return run_hil(*o); };
}, Interrupt::kPolls);

}  // namespace
}  // namespace driftless::cli
