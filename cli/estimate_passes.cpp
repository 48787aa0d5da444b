#include "cli/estimate_passes.hpp"

#include <atomic>
#include <cstdint>
#include <exception>
#include <functional>
#include <optional>
#include <thread>
#include <utility>

#include <fmt/core.h>

#include "cli/command.hpp"
#include "cli/estimate_health.hpp"
#include "estimator/sample_tee.hpp"
#include "estimator/selfcal_choice.hpp"

namespace driftless::cli {

namespace fs = std::filesystem;

// the column groups a pass parses: the accelerometers only for a g-sensitivity calibration or
// the self-calibration; the temperatures drive the bias temperature states
log::ReaderOptions reader_options(const PassInputs& in, const est::EstimatorConfig& cfg) {
  log::ReaderOptions read_opt;
  read_opt.fields = kFieldRefQ | kFieldTrueBias | kFieldTemp;
  if (in.calib || cfg.self_calibration || cfg.box_at_rest) read_opt.fields |= kFieldAccel;
  return read_opt;
}

log::ReaderOptions first_reader_options(const PassInputs& in, const est::EstimatorConfig& cfg, est::SelfcalMode mode) {
  log::ReaderOptions read_opt = reader_options(in, cfg);
  // the automatic choice may hand the rows on to the self-calibrating pass: its columns too (only
  // for a file: a stream is never read twice, so its second pass never comes, nor a re-read below)
  std::error_code ec;
  if (mode == est::SelfcalMode::kAuto && fs::is_regular_file(in.log, ec)) read_opt.fields |= kFieldAccel;
  return read_opt;
}

namespace {

bool stop_polled() { return stop_requested().load(); }

// what drives the g-sensitivity states is in the log: both accel triads (a pass without the
// self-calibration does not parse them) or ref_q
bool gravity_logged(const log::LogReader& reader) { return (reader.header_fields() & (kFieldAccel | kFieldRefQ)) != 0; }

// The early sign that the six-state model fails (the self-calibrating pass then starts beside it on
// the second core, so that a log that needs it costs about one pass of wall time, not two): at least
// kEarlyRejectedFraction of the first kEarlyUpdates or more updates rejected. Only a head start: the
// choice is made on the whole passes (estimator/selfcal_choice.hpp). Forwards everything to the files.
constexpr std::uint64_t kEarlyUpdates = 12;
constexpr double kEarlyRejectedFraction = 0.2;

class EarlyWatch : public est::EstimateSink {
 public:
  EarlyWatch(est::EstimateSink& next, std::function<void()> fire) : next_(next), fire_(std::move(fire)) {}
  void on_sample(const Sample& s, const est::SampleOutput& o, bool locked) override { next_.on_sample(s, o, locked); }
  void on_update(const est::UpdateRecord& r, const est::Matrix6d& P, const Sample& s, bool locked) override {
    next_.on_update(r, P, s, locked);
    ++updates_;
    if (!r.accepted) ++rejected_;
    if (!fired_ && updates_ >= kEarlyUpdates && double(rejected_) >= kEarlyRejectedFraction * double(updates_)) {
      fired_ = true;
      fire_();
    }
  }
  void on_attitude(const est::AttitudePoint& p) override { next_.on_attitude(p); }

 private:
  est::EstimateSink& next_;
  std::function<void()> fire_;
  std::uint64_t updates_ = 0, rejected_ = 0;
  bool fired_ = false;
};

// Where a pass's rows come from: its reader itself, or (`next`) the rows another pass read from it,
// which fill the column groups `fields`, the reader's header `header` copied before it was read
struct RowSource {
  const est::SampleSource* next = nullptr;
  std::uint32_t fields = 0;
  const log::Metadata* header = nullptr;
};

EstimatePass run_filter_pass(const PassInputs& a, const est::EstimatorConfig& cfg, log::LogReader& reader,
                             const fs::path& dir, EstimateFilesOptions file_opt, bool (*should_stop)() = &stop_polled,
                             const std::function<void()>& early = {}, bool progress = true, RowSource rows = {}) {
  EstimatePass p;
  p.cfg = cfg;
  p.dir = dir;
  p.read_opt = reader_options(a, cfg);
  // the progress display reads the log's duration (none for the pass beside another)
  file_opt.t_end_s = progress ? reader.metadata().get_number("duration_s", kNaN) : kNaN;
  p.files = std::make_unique<EstimateFiles>(dir, file_opt);
  est::EstimateRunOptions run_opt;
  run_opt.attitude_start_sigma_dps = a.attitude_start_sigma_dps;
  if (a.smooth) p.smoother = std::make_unique<est::FixedIntervalSmoother>(cfg.q_dps2_per_s());
  run_opt.update_observer = p.smoother.get();
  // the files directly, or through the watch that may start the self-calibrating pass early
  EarlyWatch watch(*p.files, early);
  est::EstimateSink* sink = early ? static_cast<est::EstimateSink*>(&watch) : p.files.get();
  p.summary = rows.next == nullptr
                  ? est::run_estimate(reader, cfg, sink, run_opt, should_stop)
                  : est::run_estimate(*rows.header, reader, rows.fields, *rows.next, cfg, sink, run_opt, should_stop);
  return p;
}

// the self-calibrating pass of the model choice, in DIR/.selfcal-pass: started beside the six-state
// pass on the second core when that one fails early (EarlyWatch), or after it; abandoned (its files
// discarded) when the choice does not want it. The destructor abandons a pass still running.
class SelfcalPass {
 public:
  SelfcalPass(const PassInputs& a, const est::EstimatorConfig& six_cfg, const fs::path& dir,
              const EstimateFilesOptions& file_opt)
      : a_(a), cfg_(six_cfg), staging_(dir / ".selfcal-pass"), file_opt_(file_opt) {
    cfg_.self_calibration = true;
    cfg_.validate();
  }
  ~SelfcalPass() { abandon(); }
  SelfcalPass(const SelfcalPass&) = delete;
  SelfcalPass& operator=(const SelfcalPass&) = delete;

  /// The rows the six-state pass reads, from `reader` (its header `header`), handed on through
  /// `tee`: start() then takes them instead of reading the log again, while the tee has them all.
  void share(est::SampleTee& tee, log::LogReader& reader, const log::Metadata& header) {
    tee_ = &tee;
    shared_reader_ = &reader;
    header_ = &header;
  }
  /// Starts the pass on a thread of its own (no progress display: the six-state pass shows its own).
  void start() {
    if (thread_.joinable()) return;
    started_ = true;
    const bool shared = tee_ != nullptr && tee_->attach();
    thread_ = std::thread([this, shared] {
      try {
        result_ = shared ? run_shared() : run(&abandon_polled, false);
      } catch (...) {
        error_ = std::current_exception();
      }
      // a pass that stopped early reads no more: the six-state pass must not wait for it
      if (tee_ != nullptr) tee_->detach();
    });
  }
  bool started() const { return started_; }
  /// The pass's result: the one started early (joined), or a pass run now. Its folder is then the
  /// caller's: kept for commit_pass(), or removed with discard().
  EstimatePass take() {
    taken_ = true;
    if (!thread_.joinable()) return run(&stop_polled, true);
    thread_.join();
    if (error_) std::rethrow_exception(error_);
    return std::move(*result_);
  }
  /// A pass taken and not kept: its files and folder go.
  void discard(EstimatePass&& p) {
    p.files.reset();
    remove_folder();
  }
  /// Stops a pass still running (not taken) and removes its folder.
  void abandon() {
    if (taken_) return;
    if (thread_.joinable()) {
      if (tee_ != nullptr) tee_->detach();
      abandoned().store(true);
      thread_.join();
      abandoned().store(false);
    }
    result_.reset();
    remove_folder();
  }

 private:
  static std::atomic<bool>& abandoned() {
    static std::atomic<bool> flag{false};
    return flag;
  }
  static bool abandon_polled() { return stop_requested().load() || abandoned().load(); }
  void remove_folder() {
    if (!started_) return;
    std::error_code ec;
    fs::remove_all(staging_, ec);
  }
  EstimatePass run(bool (*should_stop)(), bool progress) {
    started_ = true;
    fs::create_directories(staging_);
    log::LogReader again(a_.log, reader_options(a_, cfg_));
    return run_filter_pass(a_, cfg_, again, staging_, file_opt_, should_stop, {}, progress);
  }
  // on the six-state pass's rows; the tee ends them where that pass stopped reading
  EstimatePass run_shared() {
    fs::create_directories(staging_);
    const est::SampleSource next = [this](Sample& s) { return tee_->next(s); };
    const RowSource rows{&next, shared_reader_->fields(), header_};
    return run_filter_pass(a_, cfg_, *shared_reader_, staging_, file_opt_, &abandon_polled, {}, false, rows);
  }
  const PassInputs& a_;
  est::EstimatorConfig cfg_;
  fs::path staging_;
  EstimateFilesOptions file_opt_;
  est::SampleTee* tee_ = nullptr;
  log::LogReader* shared_reader_ = nullptr;
  const log::Metadata* header_ = nullptr;
  std::thread thread_;
  std::optional<EstimatePass> result_;
  std::exception_ptr error_;
  bool started_ = false;
  bool taken_ = false;
};

// the default model choice (estimator/selfcal_choice.hpp): when the six-state pass shows an error
// the self-calibration models, the log again with it, in a folder of its own; the better pass is
// kept. `choice` records what was done for summary.json.
EstimatePass choose_model(const PassInputs& a, EstimatePass six, SelfcalPass& sc_pass, bool gravity,
                          SelfcalChoice& choice) {
  const est::SelfcalTrigger trig = est::selfcal_trigger(six.summary.health, gravity);
  if (choice.mode != est::SelfcalMode::kAuto || !trig.wanted || stop_requested().load()) {
    sc_pass.abandon();
    return six;
  }
  if (!fs::is_regular_file(a.log)) {
    // a stream (a FIFO) cannot be read a second time
    fmt::print(stderr, "driftless estimate: the six-state model does not fit this log (finding {}), and the log is "
                       "not a regular file, so it cannot be read again in the self-calibrating mode: save it and "
                       "run with --selfcal\n", cause_key(trig.cause));
    return six;
  }
  choice.tried = true;
  choice.cause = trig.cause;
  choice.six_state = six.summary.health;
  const est::HealthReport& h = six.summary.health;
  fmt::print(stderr,
             "driftless estimate: the six-state model does not fit this log (verdict {}, finding {}; {} of {} "
             "updates rejected, NIS mean {:.3g}): {} in the self-calibrating mode (--selfcal: g-sensitivity, "
             "scale/misalignment and end-stop states; --no-selfcal keeps the six-state model)\n",
             est::to_string(h.verdict), cause_key(trig.cause), h.rejected, h.updates, h.nis_mean,
             sc_pass.started() ? "estimated beside it" : "estimating again");
  EstimatePass sc;
  try {
    sc = sc_pass.take();
  } catch (const log::LogError& e) {
    // the accel columns, which only the self-calibrating pass parses, may be what it refuses:
    // the six-state results stand, and the reason is said (a full disk still ends the run)
    choice.error = e.what();
    sc_pass.discard(std::move(sc));
    return six;
  }
  choice.selfcal = sc.summary.health;
  choice.interrupted = stop_requested().load();
  choice.used = !choice.interrupted && est::selfcal_pass_better(sc.summary.health, six.summary.health);
  if (!choice.used) {
    sc_pass.discard(std::move(sc));
    return six;
  }
  six.files.reset();
  return sc;
}

}  // namespace

EstimatePass run_passes(const PassInputs& in, const est::EstimatorConfig& cfg, log::LogReader& reader,
                        const fs::path& dir, const EstimateFilesOptions& file_opt, SelfcalChoice& choice) {
  const bool gravity = gravity_logged(reader);
  const log::Metadata header = reader.metadata();  // before any row: what a reader of its own starts with
  // in the automatic choice the self-calibrating pass may start early, beside the six-state pass, on
  // the rows that pass reads (one parse for both)
  const bool automatic = choice.mode == est::SelfcalMode::kAuto && gravity && fs::is_regular_file(in.log);
  est::SampleTee tee;
  SelfcalPass sc_pass(in, cfg, dir, file_opt);
  std::function<void()> early;
  if (automatic) {
    sc_pass.share(tee, reader, header);
    early = [&sc_pass] { sc_pass.start(); };
  }
  // the six-state pass sees its rows as a reader of its own options would give them: without the
  // accel columns read for the other pass
  const bool mask = (reader.fields() & kFieldAccel) != 0 && (reader_options(in, cfg).fields & kFieldAccel) == 0;
  const est::SampleSource next = [&](Sample& s) {
    if (!reader.next(s)) return false;
    if (automatic) tee.offer(s);
    if (mask) {
      s.accel1_mps2.setConstant(kNaN);
      s.accel2_mps2.setConstant(kNaN);
    }
    return true;
  };
  const RowSource rows{&next, mask ? reader.fields() & ~kFieldAccel : reader.fields(), &reader.metadata()};
  EstimatePass six;
  try {
    six = run_filter_pass(in, cfg, reader, dir, file_opt, &stop_polled, early, true, rows);
  } catch (const log::LogError&) {
    tee.detach();
    sc_pass.abandon();
    if (!mask || reader.refused_group() != kFieldAccel || !fs::is_regular_file(in.log)) throw;
    // an accel value, which the six-state pass does not read, is what the reader refused: that
    // pass again on a reader of its own (the self-calibrating pass then says what it refused)
    log::LogReader own(in.log, reader_options(in, cfg));
    SelfcalPass again(in, cfg, dir, file_opt);
    return choose_model(in, run_filter_pass(in, cfg, own, dir, file_opt), again, gravity, choice);
  }
  tee.end();
  return choose_model(in, std::move(six), sc_pass, gravity, choice);
}

// the kept pass's files into place: a self-calibrating pass wrote into its own folder
void commit_pass(EstimatePass& p, const fs::path& dir) {
  p.files->commit();
  if (p.dir == dir) return;
  for (const char* name : {"estimate.csv", "attitude.csv", "corrected.csv"}) {
    if (fs::exists(p.dir / name)) fs::rename(p.dir / name, dir / name);
  }
  fs::remove_all(p.dir);
}

// the console line after a self-calibrating pass that was tried
void print_choice(const SelfcalChoice& c) {
  if (!c.tried) return;
  const auto rej = [](const est::HealthReport& h) { return 100.0 * h.rejected_fraction; };
  if (!c.error.empty()) {
    fmt::print(stderr, "driftless estimate: the self-calibrating pass could not read the log ({}): these are the "
                       "six-state results; fix the log (or --no-selfcal)\n", c.error);
  } else if (c.interrupted) {
    fmt::print(stderr, "driftless estimate: the self-calibrating pass was interrupted: the outputs are the "
                       "six-state pass's\n");
  } else if (c.used) {
    fmt::print("  self-calibration (auto): used; its verdict {} ({:.1f} % rejected) against the six-state "
               "model's {} ({:.1f} % rejected)\n",
               est::to_string(c.selfcal.verdict), rej(c.selfcal), est::to_string(c.six_state.verdict),
               rej(c.six_state));
  } else {
    fmt::print(stderr,
               "driftless estimate: self-calibration (auto) tried and not used: it fits no better (verdict {}, "
               "{:.1f} % rejected, NIS mean {:.3g} against the top of its band {:.3g}; the six-state model: {}, "
               "{:.1f} % rejected), so these are the six-state results; an excess both models leave is noise or "
               "wander larger than configured, or an error neither models (see the findings)\n",
               est::to_string(c.selfcal.verdict), rej(c.selfcal), c.selfcal.nis_mean, c.selfcal.nis_mean_band_hi,
               est::to_string(c.six_state.verdict), rej(c.six_state));
  }
}


}  // namespace driftless::cli
