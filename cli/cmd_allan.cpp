// driftless allan: Allan, modified Allan and Hadamard deviations with confidence intervals, the
// joint noise fit (Q, N, B, K, R), Kalibr / OpenVINS / VINS-Mono noise files, plots and the
// round-trip check, from a measurement log or any recording the importers read. docs/allan.md.
#include <algorithm>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "cli/allan_result.hpp"
#include "cli/command.hpp"
#include "estimator/allan_fit.hpp"

namespace driftless::cli {
namespace {

namespace fs = std::filesystem;
using allan::Result;

struct AllanArgs {
  allan::InputArgs input;
  std::string out, taus = "octave", devs = "adev", datasheet, gaps = "split";
  bool all_tau = false, non_overlapping = false, plot = false, stream = false, exact = false, strict = false;
  std::size_t exact_up_to = 65536;
  double confidence = 0.683;
  std::size_t validate = 0;
  std::uint64_t seed = 1;
  allan::ExportOptions exports;
};

// --taus: octave, decade, N/decade, all, or a list of seconds "1,10,100"
void apply_taus(const std::string& spec, est::AllanOptions& o) {
  if (spec == "octave") return void(o.spacing = est::TauSpacing::kOctave);
  if (spec == "decade") return void(o.spacing = est::TauSpacing::kDecade);
  if (spec == "all") return void(o.spacing = est::TauSpacing::kAll);
  const auto slash = spec.find("/decade");
  if (slash != std::string::npos) {
    o.spacing = est::TauSpacing::kPerDecade;
    o.points_per_decade = std::stoi(spec.substr(0, slash));
    return;
  }
  o.spacing = est::TauSpacing::kExplicit;
  for (const auto& t : allan::split_list(spec)) {
    std::size_t used = 0;
    double v = 0.0;
    try {
      v = std::stod(t, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used != t.size()) {
      throw std::invalid_argument("--taus: expected octave, decade, N/decade, all or a list of seconds (1,10,100), got '" +
                                  spec + "'");
    }
    o.tau_s.push_back(v);
  }
}

std::vector<est::Deviation> parse_devs(const std::string& s) {
  std::vector<est::Deviation> out;
  for (const auto& d : allan::split_list(s)) {
    bool known = false;
    for (const auto dev : {est::Deviation::kAllan, est::Deviation::kModifiedAllan, est::Deviation::kHadamard}) {
      if (d == est::to_string(dev)) out.push_back(dev), known = true;
    }
    if (!known) throw std::invalid_argument("--dev: expected a list of adev, mdev, hdev, got '" + s + "'");
  }
  if (out.empty()) throw std::invalid_argument("--dev: give at least one of adev, mdev, hdev");
  return out;
}

// the streaming pass serves octave Allan / Hadamard curves of imported binary inputs
bool use_stream(const AllanArgs& a, const est::AllanOptions& base, const std::vector<est::Deviation>& devs) {
  const bool fits = base.spacing == est::TauSpacing::kOctave && base.overlapping &&
                    std::none_of(devs.begin(), devs.end(), [](est::Deviation d) { return d == est::Deviation::kModifiedAllan; });
  if (a.stream && !fits) {
    throw std::invalid_argument("--stream: the streaming pass gives octave taus of adev and hdev, overlapping only");
  }
  if (a.stream) return true;
  if (a.exact || !fits || !allan::is_imported(a.input)) return false;
  const auto f = importers::detect_format(a.input.source());
  return f == importers::Format::kNpy || f == importers::Format::kBag;
}

est::AllanOptions fit_options(double rate_hz, double confidence) {
  est::AllanOptions o;
  o.sample_rate_hz = rate_hz;
  o.confidence = confidence;
  return o;
}

void fill_from_stream(Result& r, const AllanArgs& a, const est::AllanOptions& base, std::vector<est::Deviation> devs) {
  if (std::find(devs.begin(), devs.end(), est::Deviation::kAllan) == devs.end()) devs.push_back(est::Deviation::kAllan);
  auto s = allan::stream_octaves(a.input, devs, base.confidence, a.exact_up_to);
  r.format = s.meta.format, r.rate_hz = s.meta.rate_hz, r.notes = s.meta.notes, r.stamps = s.meta.stamps;
  r.warnings = s.warnings;
  for (std::size_t c = 0; c < s.meta.channels.size(); ++c) {
    allan::ChannelResult ch{s.meta.channels[c].name, s.meta.channels[c].quantity, s.meta.channels[c].axis, {}, {}, {}, {}};
    for (std::size_t d = 0; d < devs.size(); ++d) {
      if (devs[d] == est::Deviation::kAllan) ch.fit_curve = s.curves[c][d];
      if (d < r.deviations.size()) ch.curves.push_back(s.curves[c][d]);
    }
    r.samples = std::max(r.samples, ch.fit_curve.samples);
    r.channels.push_back(std::move(ch));
  }
}

void fill_in_memory(Result& r, const AllanArgs& a, est::AllanOptions base) {
  allan::Loaded L = allan::load(a.input);
  r.format = L.format, r.rate_hz = L.rate_hz, r.notes = L.notes, r.stamps = L.stamps;
  r.warnings = allan::motion_warnings(L);
  base.sample_rate_hz = L.rate_hz;
  Progress progress("allan");
  for (std::size_t c = 0; c < L.channels.size(); ++c) {
    const auto& in = L.channels[c];
    progress.update(static_cast<double>(c) / static_cast<double>(L.channels.size()), in.name);
    if (in.x.size() < 3) throw std::invalid_argument(fmt::format("{}: channel {} has only {} samples", a.input.source(), in.name, in.x.size()));
    allan::ChannelResult ch{in.name, in.quantity, in.axis, {}, {}, {}, {}};
    for (const auto d : r.deviations) {
      est::AllanOptions o = base;
      o.deviation = d;
      if (d == est::Deviation::kModifiedAllan) o.overlapping = true;
      ch.curves.push_back(est::allan_deviation(in.x, o, in.segment_starts));
    }
    const bool reuse = base.spacing == est::TauSpacing::kOctave && base.overlapping && r.deviations[0] == est::Deviation::kAllan;
    ch.fit_curve = reuse ? ch.curves[0] : est::allan_deviation(in.x, fit_options(L.rate_hz, base.confidence), in.segment_starts);
    r.samples = std::max(r.samples, in.x.size());
    r.channels.push_back(std::move(ch));
  }
  progress.done();
}

int run_allan(AllanArgs a) {
  a.input.gaps_ignore = a.gaps == "ignore";
  Result r;
  r.source = a.input.source();
  r.deviations = parse_devs(a.devs);
  r.datasheet = allan::parse_datasheet(a.datasheet);
  est::AllanOptions base;
  base.overlapping = !a.non_overlapping;
  base.confidence = a.confidence;
  apply_taus(a.all_tau ? "all" : a.taus, base);
  if (use_stream(a, base, r.deviations)) fill_from_stream(r, a, base, r.deviations);
  else fill_in_memory(r, a, base);
  for (auto& ch : r.channels) ch.fit = est::fit_noise_parameters(ch.fit_curve);
  if (a.validate > 0) allan::validate_round_trip(r, a.validate, a.seed);
  fs::create_directories(a.out);
  allan::write_tables(a.out, r);
  allan::write_fit_json(a.out, r);
  const auto files = allan::write_exports(a.out, r, a.exports);
  allan::print_summary(r);
  for (const auto& f : files) fmt::print("  wrote {}\n", f.string());
  if (a.plot) {
    for (const auto& w : allan::write_plots(a.out, r)) fmt::print(stderr, "driftless allan: warning: {}\n", w);
  }
  for (const auto& w : r.warnings) fmt::print(stderr, "driftless allan: warning: {}\n", w);
  if (a.strict && !r.warnings.empty()) {
    fmt::print(stderr, "driftless allan: --strict: {} warning(s) about the record: exit 1\n", r.warnings.size());
    return 1;
  }
  return 0;
}

void add_input_options(CLI::App* cmd, AllanArgs& a) {
  auto& in = a.input;
  auto* log_opt = cmd->add_option("--log", in.log, "Measurement log (driftless-log 1)")->check(CLI::ExistingFile);
  auto* in_opt = cmd->add_option("--in", in.in, "Any IMU recording: delimited text, EuRoC/TUM-VI imu0/data.csv, .npy, ROS 1 bag "
                                                "(docs/import.md)")->check(CLI::ExistingFile);
  auto* csv_opt = cmd->add_option("--csv", in.csv, "Same as --in FILE --format text")->check(CLI::ExistingFile);
  log_opt->excludes(in_opt)->excludes(csv_opt);
  in_opt->excludes(csv_opt);
  allan::add_import_options(cmd, in);
  cmd->add_option("--gaps", a.gaps, "At gaps in the stamps or missing values: split (gap-aware, default) or ignore")
      ->check(CLI::IsMember({"split", "ignore"}));
}

const bool registered_allan = register_command(40, [](CLI::App& app) {
  auto* cmd = app.add_subcommand("allan",
                                 "Allan / modified Allan / Hadamard deviations (deg/s vs tau in s) with NIST SP 1065 "
                                 "intervals, joint fit of Q, N, B, K, R, noise files for Kalibr, OpenVINS, VINS-Mono");
  auto a = std::make_shared<AllanArgs>();
  add_input_options(cmd, *a);
  cmd->add_option("--out", a->out, "Output folder: allan.csv, allan_points.csv, allan_fit.json [, noise files, plots]")->required();
  cmd->add_option("--taus", a->taus, "Averaging times: octave (default), decade, N/decade (e.g. 10/decade), all, or seconds 1,10,100");
  cmd->add_flag("--all-tau", a->all_tau, "Same as --taus all (every m: slow on long records)");
  cmd->add_option("--dev", a->devs, "Deviations: any of adev, mdev, hdev, comma-separated (default adev)");
  cmd->add_flag("--non-overlapping", a->non_overlapping, "Non-overlapping clusters (the paper's definition; adev, hdev)");
  cmd->add_option("--confidence", a->confidence, "Two-sided probability of the intervals (default 0.683)")->check(CLI::Range(0.01, 0.999));
  cmd->add_flag("--stream", a->stream, "Bounded memory: octave taus accumulated while reading (default for .npy and bags)");
  cmd->add_flag("--exact", a->exact, "Read the whole record into memory: exact at every tau");
  cmd->add_option("--exact-up-to", a->exact_up_to, "Streaming: every difference is used up to this m (a power of two; default 65536)");
  cmd->add_flag("--corrected", a->input.corrected, "Log only: also the DriftLess-corrected gyro channels, side by side");
  cmd->add_option("--config", a->input.config, "Estimator configuration for --corrected (docs/estimator.md)")->check(CLI::ExistingFile);
  cmd->add_option("--mode", a->input.mode, "Estimator mode for --corrected: paper or general")->check(CLI::IsMember({"paper", "general"}));
  cmd->add_option("--corrected-lock-sigma", a->input.corrected_lock_sigma_dps,
                  "deg/s: the corrected channels start once every sigma of the correction is below this "
                  "(the filter has locked on); 0 starts them at the first sample")
      ->capture_default_str()
      ->check(non_negative_number("deg/s"));
  cmd->add_option("--datasheet", a->datasheet, "Datasheet values to draw: N=<deg/s/rtHz>,B=<deg/s>,K=<deg/s/rts>");
  cmd->add_flag("--kalibr", a->exports.kalibr, "Write Kalibr imu.yaml (aggregated) and imu_<channel>.yaml (per axis), SI units");
  cmd->add_flag("--imu-yaml", a->exports.kalibr, "Same as --kalibr");
  cmd->add_flag("--openvins", a->exports.openvins, "Write OpenVINS kalibr_imu_chain.yaml");
  cmd->add_flag("--vins-mono", a->exports.vins_mono, "Write the VINS-Mono IMU noise block (vins_mono_imu.yaml)");
  cmd->add_option("--inflate", a->exports.inflate, "Multiply exported noise densities and random walks by this (default 1)")
      ->check(CLI::Range(1.0, 1000.0));
  cmd->add_option("--export-topic", a->exports.topic, "rostopic written into the noise files (default /imu0)");
  cmd->add_option("--validate", a->validate, "Simulate N records from the fit with the twin's sensor model; 95 % band and verdict")
      ->check(count_number(0, 10000));
  cmd->add_option("--seed", a->seed, "Seed of --validate, 0 .. 2^64-1 (default 1)")->check(seed_number());
  cmd->add_flag("--strict", a->strict, "Exit 1 when the record makes the figures wrong for the sensor (it is not at rest)");
  cmd->add_flag("--plot", a->plot, "Also write allan.png/svg and allan_<channel>.png/svg with their gnuplot scripts");
  return [a] { return run_allan(*a); };
});

}  // namespace
}  // namespace driftless::cli
