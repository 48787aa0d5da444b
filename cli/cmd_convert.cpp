// driftless convert: any IMU recording the importers read (delimited text, EuRoC/TUM-VI, .npy,
// ROS 1 bags) into the documented measurement log, single-sensor form (docs/import.md, "convert").
// The log then goes to check, allan and (with a reference attitude) compare/diagnose.
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <fmt/format.h>

#include "cli/allan_input.hpp"
#include "cli/command.hpp"
#include "estimator/input_error.hpp"
#include "estimator/log.hpp"
#include "estimator/log_metadata.hpp"
#include "importers/ground_truth.hpp"
#include "importers/imu_reader.hpp"
#include "importers/stamps.hpp"

namespace driftless::cli {
namespace {

using importers::Quantity;

enum class TimeBase { kAuto, kStamps, kUniform };

struct ConvertArgs {
  allan::InputArgs input;
  std::string out;
  std::string time = "auto";       // auto | stamps | uniform
  double full_scale_dps = 0.0;     // deg/s, the gyro's range for the log's plausibility check
  std::string source_name;         // free text for the log's 'source' key
  std::string ref;                 // ground truth to join into ref_q / ref_p (EuRoC / Vicon layout)
  double ref_max_gap_s = 0.0;      // s, a longer ground-truth step is a gap (0: 10 median steps)
};

/// Where each log column comes from in the importer's channels (-1: absent).
struct ChannelMap {
  int gyro[3] = {-1, -1, -1};
  int accel[3] = {-1, -1, -1};
  int temp = -1;
  bool has_accel() const { return accel[0] >= 0 && accel[1] >= 0 && accel[2] >= 0; }
};

ChannelMap map_channels(const importers::StreamInfo& info) {
  ChannelMap m;
  int rates = 0;
  for (std::size_t c = 0; c < info.channels.size(); ++c) {
    const auto& ch = info.channels[c];
    const int i = static_cast<int>(c);
    if (ch.quantity == Quantity::kRate) {
      ++rates;
      if (ch.axis >= 0 && ch.axis < 3 && m.gyro[ch.axis] < 0) m.gyro[ch.axis] = i;
    } else if (ch.quantity == Quantity::kAccel) {
      if (ch.axis >= 0 && ch.axis < 3 && m.accel[ch.axis] < 0) m.accel[ch.axis] = i;
    } else if (ch.quantity == Quantity::kTemperature && m.temp < 0) {
      m.temp = i;
    }
  }
  std::string names;
  for (const auto& ch : info.channels) names += (names.empty() ? "" : ", ") + ch.name;
  if (m.gyro[0] < 0 || m.gyro[1] < 0 || m.gyro[2] < 0) {
    throw InputError(info.source, 0, "",
                     fmt::format("convert needs one gyro triad (x, y, z); the channels read are [{}]: name them "
                                 "with --columns GX,GY,GZ (names or 1-based indices)", names));
  }
  if (rates > 3) {
    throw InputError(info.source, 0, "",
                     fmt::format("{} rate channels [{}]: the log holds one sensor (the single-sensor form); "
                                 "pick its triad with --columns GX,GY,GZ", rates, names));
  }
  return m;
}

TimeBase parse_time_base(const std::string& s) {
  if (s == "stamps") return TimeBase::kStamps;
  if (s == "uniform") return TimeBase::kUniform;
  return TimeBase::kAuto;
}

/// First pass over a stamped input: what its stamps do (gaps, bursts, steps back).
importers::StampReport survey_stamps(const std::filesystem::path& in, const importers::ImportOptions& opt) {
  auto reader = importers::open_imu(in, opt);
  importers::StampMonitor mon;
  importers::ImuBlock block;
  bool learned = false;
  while (reader->read(block, 65536)) {
    if (!learned) {
      mon.learn(block.t_s);
      learned = true;
    }
    for (std::size_t r = 0; r < block.rows(); ++r) mon.push(block.t_s[r], block.loc[r]);
    if (stop_requested()) break;
  }
  return mon.report();
}

/// How rows get their time: the stamps (strictly increasing, regular or with gaps), or k / rate.
struct TimePlan {
  bool uniform = false;
  double rate_hz = kNaN;  // Hz, the log's sample_rate_hz
  double t0_s = 0.0;      // s, the first row's time on the uniform base
  std::vector<std::string> notes;
};

/// --time auto falls back on t = t0 + k / rate when the stamps repeat or go back. That is right
/// when every sample is there (a logger that stamped one row twice); when samples are missing as
/// well (gaps), it moves every row after a gap to an earlier time and hides the gap. Refused then:
/// the last row's k / rate time against its stamp tells, whatever the mix of repeats and gaps.
void refuse_shifting_uniform_time(const importers::StreamInfo& info, const importers::StampReport& st,
                                  const TimePlan& p) {
  if (st.rows < 2 || !std::isfinite(st.last_t_s) || !(p.rate_hz > 0.0)) return;
  const double last_uniform_s = p.t0_s + static_cast<double>(st.rows - 1) / p.rate_hz;
  const double shift_s = st.last_t_s - last_uniform_s;  // s, how far k / rate moves the last row
  if (!(std::fabs(shift_s) > 0.5 / p.rate_hz)) return;
  throw InputError(
      info.source, 0, "--time",
      fmt::format("the stamps cannot be the log's time ({}), and t = first stamp + k / {:.6g} Hz would move the "
                  "last row {:.6g} s {} its stamp ({}): samples are missing, so a uniform time puts every row after "
                  "a gap at the wrong time. Repair the stamps that repeat or go back (the rows keep their time "
                  "then), or give --time uniform to accept the shift",
                  fmt::join(st.describe("line"), "; "), p.rate_hz, std::fabs(shift_s),
                  shift_s > 0 ? "before" : "after", fmt::format("{:.6f} s against {:.6f} s", last_uniform_s, st.last_t_s)));
}

TimePlan plan_time(const ConvertArgs& a, const importers::StreamInfo& info, const importers::StampReport& st) {
  TimePlan p;
  const TimeBase want = parse_time_base(a.time);
  if (!info.has_time && want == TimeBase::kStamps) {
    throw InputError(info.source, 0, "--time", "stamps asked for, but the rows carry no time");
  }
  p.rate_hz = allan::resolve_rate(a.input.rate_hz, info.nominal_rate_hz, st, p.notes, info.source);
  const bool stamps_usable = info.has_time && st.backwards == 0 && st.repeated == 0 && !st.bursty;
  p.uniform = want == TimeBase::kUniform || !info.has_time || (want == TimeBase::kAuto && !stamps_usable);
  if (!p.uniform && !stamps_usable) {
    throw InputError(info.source, 0, "--time",
                     fmt::format("the stamps cannot be the log's time (it must increase strictly): {}; "
                                 "give --time uniform to write t = t0 + k / rate",
                                 fmt::join(st.describe("line"), "; ")));
  }
  if (info.has_time) p.t0_s = st.first_t_s;
  if (want == TimeBase::kAuto && p.uniform && info.has_time) refuse_shifting_uniform_time(info, st, p);
  if (info.has_time && info.epoch_s != 0) {
    p.notes.push_back(fmt::format("t counts from the epoch {} s (the first stamp floored to whole seconds): "
                                  "t = stamp - {} s, formed in integer ns", info.epoch_s, info.epoch_s));
  }
  if (!p.uniform) {
    p.notes.push_back("t = the stamps");
  } else if (!info.has_time) {
    p.notes.push_back(fmt::format("t = k / {:.6g} Hz (the rows carry no time)", p.rate_hz));
  } else {
    const char* why = want == TimeBase::kUniform ? "--time uniform"
                      : st.bursty                ? "the stamps are bursty arrival times"
                                                 : "the stamps are not strictly increasing";
    p.notes.push_back(fmt::format("t = first stamp + k / {:.6g} Hz ({})", p.rate_hz, why));
  }
  return p;
}

log::Metadata convert_metadata(const ConvertArgs& a, const importers::StreamInfo& info, const TimePlan& tp) {
  log::LogInfo li;
  li.sample_rate_hz = tp.rate_hz;
  li.source = !a.source_name.empty()
                  ? a.source_name
                  : fmt::format("driftless convert from {} ({})", info.source, importers::to_string(info.format));
  log::Metadata meta;
  log::write_log_info(meta, li);
  if (a.full_scale_dps > 0.0) log::set_number(meta, "gyro_full_scale_dps", a.full_scale_dps);
  return meta;
}

Sample sample_of(const importers::ImuBlock& b, std::size_t r, const ChannelMap& m, double t_s) {
  Sample s;
  s.t_s = t_s;
  for (int k = 0; k < 3; ++k) s.gyro1_dps[k] = b.values[static_cast<std::size_t>(m.gyro[k])][r];
  if (m.has_accel()) {
    for (int k = 0; k < 3; ++k) s.accel1_mps2[k] = b.values[static_cast<std::size_t>(m.accel[k])][r];
  }
  if (m.temp >= 0) s.temp1_c = b.values[static_cast<std::size_t>(m.temp)][r];
  s.plat1_deg = 0.0;  // the sensor is fixed to the box
  return s;
}

/// The ground truth joined onto the rows (--ref): the attitude by slerp, the position linearly;
/// rows outside its span are trimmed, rows inside a gap of it get no reference (empty ref_*).
struct RefJoin {
  importers::GroundTruth gt;
  std::unique_ptr<importers::PoseInterpolator> at;
  std::uint64_t before = 0, after = 0, in_gaps = 0;
  std::vector<std::string> notes;
  /// Fills the sample's ref_q / ref_p; false when the row is to be trimmed.
  bool attach(Sample& s);
};

std::unique_ptr<RefJoin> open_ref(const ConvertArgs& a, const importers::StreamInfo& info,
                                  const importers::StampReport& st, const TimePlan& tp) {
  if (a.ref.empty()) return nullptr;
  if (!info.has_time) {
    throw InputError(info.source, 0, "--ref", "the rows carry no time, so a ground truth cannot be joined onto them");
  }
  auto j = std::make_unique<RefJoin>();
  j->gt = importers::read_ground_truth(a.ref);
  const auto max_gap_ns = a.ref_max_gap_s > 0.0 ? static_cast<std::int64_t>(std::llround(a.ref_max_gap_s * 1e9))
                                                : 10 * j->gt.median_step_ns;
  j->at = std::make_unique<importers::PoseInterpolator>(j->gt, info.epoch_s, max_gap_ns);
  const double imu_last_s = tp.uniform ? tp.t0_s + static_cast<double>(st.rows - 1) / tp.rate_hz : st.last_t_s;
  if (j->at->last_s() < tp.t0_s || j->at->first_s() > imu_last_s) {
    throw InputError(a.ref, 0, "--ref",
                     fmt::format("the ground truth spans {:.6f}..{:.6f} s and the IMU rows {:.6f}..{:.6f} s "
                                 "(s since the epoch {} s): they do not overlap",
                                 j->at->first_s(), j->at->last_s(), tp.t0_s, imu_last_s, info.epoch_s));
  }
  j->notes.push_back(fmt::format(
      "ref_q, ref_p = {} ({} poses, median step {:.6g} ms, quaternion columns q {} as the header names them): attitude "
      "by slerp, position linearly, onto the IMU times; its frame is taken as the log's reference frame (q_enu_from_body)",
      a.ref, j->gt.poses.size(), 1e-6 * static_cast<double>(j->gt.median_step_ns), j->gt.quaternion_order));
  j->notes.push_back(fmt::format("IMU rows outside the ground truth's span {:.6f}..{:.6f} s are trimmed (left out); "
                                 "rows inside a gap of more than {:.6g} s get no reference",
                                 j->at->first_s(), j->at->last_s(), 1e-9 * static_cast<double>(max_gap_ns)));
  return j;
}

bool RefJoin::attach(Sample& s) {
  const importers::PoseAt p = at->at(s.t_s);
  switch (p.where) {
    case importers::PoseAt::Where::kBefore: return ++before, false;
    case importers::PoseAt::Where::kAfter: return ++after, false;
    case importers::PoseAt::Where::kGap: return ++in_gaps, true;  // ref_* stay NaN: written empty
    case importers::PoseAt::Where::kInside: break;
  }
  s.set_q_enu_from_body(p.q_ref_from_body);
  s.ref_p_enu_m = p.p_ref_m;
  return true;
}

/// What the join did, once the rows are written.
std::string ref_summary(const RefJoin& j) {
  return fmt::format("ref: {} rows trimmed before the ground truth's first stamp, {} after its last; {} rows in "
                     "its gaps without a reference",
                     j.before, j.after, j.in_gaps);
}

/// --full-scale states the gyro's range in the log; a reading beyond the margin the log's readers
/// allow (log::kFullScaleMargin x FS) would make every reader refuse the log, so the range given
/// is wrong: refused here, naming the input row, rather than writing a log nobody can read.
void check_full_scale(const Sample& s, const ConvertArgs& a, const std::string& source, std::uint64_t loc) {
  if (!(a.full_scale_dps > 0.0)) return;
  for (int k = 0; k < 3; ++k) {
    const double v = s.gyro1_dps[k];
    if (!(std::fabs(v) > log::kFullScaleMargin * a.full_scale_dps)) continue;
    throw InputError(source, static_cast<std::size_t>(loc), "--full-scale",
                     fmt::format("gyro {} reads {:.6g} deg/s, beyond {:g} x the --full-scale {:g} deg/s: a gyro with "
                                 "that range cannot give it, and every reader would refuse the log; give the sensor's "
                                 "real range (or leave --full-scale out)",
                                 "xyz"[k], v, log::kFullScaleMargin, a.full_scale_dps));
  }
}

int run_convert(const ConvertArgs& a) {
  const auto opt = a.input.import_options();
  auto reader = importers::open_imu(a.input.in, opt);
  const importers::StreamInfo info = reader->info();
  const ChannelMap map = map_channels(info);
  const importers::StampReport st = info.has_time ? survey_stamps(a.input.in, opt) : importers::StampReport{};
  const TimePlan tp = plan_time(a, info, st);
  const auto ref = open_ref(a, info, st, tp);
  std::uint32_t fields = kLayoutSingleSensor;
  if (map.has_accel()) fields |= kFieldAccel;
  if (map.temp >= 0) fields |= kFieldTemp;
  if (ref) fields |= kFieldRefQ | kFieldRefP;
  const std::filesystem::path out(a.out);
  if (out.has_parent_path()) std::filesystem::create_directories(out.parent_path());
  const double rows_estimate = st.rows > 0 ? static_cast<double>(st.rows) : 0.0;
  warn_if_disk_too_small("convert", out.has_parent_path() ? out.parent_path() : ".",
                         rows_estimate * log::estimated_row_bytes(fields), "the log");
  log::LogWriter writer(out, convert_metadata(a, info, tp), fields);
  for (const auto& s : info.assumptions) writer.event(tp.t0_s, "assumed: " + s);
  for (const auto& s : tp.notes) writer.event(tp.t0_s, "time: " + s);
  if (ref) {
    for (const auto& s : ref->notes) writer.event(tp.t0_s, "ref: " + s);
  }
  importers::ImuBlock block;
  std::uint64_t k = 0, written = 0;
  double last_t = tp.t0_s;
  Progress progress("convert");
  while (!stop_requested() && reader->read(block, 65536)) {
    for (std::size_t r = 0; r < block.rows(); ++r, ++k) {
      const double t = tp.uniform ? tp.t0_s + static_cast<double>(k) / tp.rate_hz : block.t_s[r];
      Sample s = sample_of(block, r, map, t);
      try {
        check_full_scale(s, a, info.source, block.loc.empty() ? k + 1 : block.loc[r]);
      } catch (const InputError& e) {
        writer.finish(false, e.what());  // the rows before stay; the log says why it stops there
        throw;
      }
      if (ref && !ref->attach(s)) continue;
      writer.write(s);
      last_t = t;
      ++written;
    }
    if (st.rows > 0) progress.update(static_cast<double>(k) / static_cast<double>(st.rows));
  }
  if (ref) writer.event(last_t, ref_summary(*ref));
  if (stop_requested()) {
    writer.finish(false, fmt::format("interrupted after {} rows", k));
    fmt::print(stderr, "driftless convert: interrupted; {} holds {} rows and says complete: false\n", a.out, k);
    return interrupted_exit_code();
  }
  writer.finish(true);
  progress.done();
  fmt::print("{} ({}): {} rows, gyro{}{}{} -> {} (single-sensor log, {:.6g} Hz, {} rows)\n", info.source,
             importers::to_string(info.format), k, map.has_accel() ? ", accel" : "", map.temp >= 0 ? ", temperature" : "",
             ref ? ", reference attitude" : "", a.out, tp.rate_hz, written);
  for (const auto& s : info.assumptions) fmt::print("  assumed: {}\n", s);
  for (const auto& s : tp.notes) fmt::print("  time: {}\n", s);
  if (ref) {
    for (const auto& s : ref->notes) fmt::print("  ref: {}\n", s);
    fmt::print("  {}\n", ref_summary(*ref));
  }
  for (const auto& s : st.describe("line")) fmt::print("  stamps: {}\n", s);
  return kExitOk;
}

const bool registered_convert = register_command(
    45,
    [](CLI::App& app) {
      auto* cmd = app.add_subcommand("convert",
                                     "An IMU recording (delimited text, EuRoC/TUM-VI imu0/data.csv, .npy, ROS 1 bag) into a "
                                     "measurement log in the single-sensor form (deg/s, m/s^2, degC, s)");
      auto a = std::make_shared<ConvertArgs>();
      cmd->add_option("--in", a->input.in, "The recording (docs/import.md)")->required()->check(CLI::ExistingFile);
      allan::add_import_options(cmd, a->input);
      cmd->add_option("--temp-column", a->input.import.temp_column, "Temperature column (degC): name or 1-based index");
      cmd->add_option("--out", a->out, "The log to write (driftless-log 1, 'sensors: 1')")->required();
      cmd->add_option("--time", a->time, "Row times: auto (the stamps when they increase regularly, else k / rate), "
                                         "stamps, or uniform")
          ->check(CLI::IsMember({"auto", "stamps", "uniform"}));
      cmd->add_option("--full-scale", a->full_scale_dps, "The gyro's range +-FS in deg/s, written as gyro_full_scale_dps "
                                                         "(MPU6050 default: 250)")
          ->check(positive_number("deg/s"));
      cmd->add_option("--source", a->source_name, "Text for the log's 'source' key (default: the file and its format)");
      auto* ref = cmd->add_option("--ref", a->ref, "Ground truth to join into ref_q/ref_p (EuRoC state_groundtruth_estimate0 or "
                                       "vicon0 data.csv: ns stamp, p x y z, q w x y z); rows outside its span are trimmed")
          ->check(CLI::ExistingFile);
      cmd->add_option("--ref-max-gap", a->ref_max_gap_s, "s: a longer step of the ground truth is a gap, rows in it get "
                                                         "no reference (default: 10 of its median steps)")
          ->check(positive_number("s"))
          ->needs(ref);
      return [a] { return run_convert(*a); };
    },
    Interrupt::kPolls);

}  // namespace
}  // namespace driftless::cli
