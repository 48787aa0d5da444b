#include "cli/estimate_outputs.hpp"

#include <algorithm>
#include <cmath>
#include <string_view>

#include <fmt/core.h>
#include <fmt/format.h>

#include "cli/estimate_health.hpp"
#include "estimator/fixed_decimal.hpp"
#include "report/json.hpp"

namespace driftless::cli {
namespace {

namespace fs = std::filesystem;

constexpr std::string_view kCorrectedHeader = "t,y1c_x,y1c_y,y1c_z,y2c_x,y2c_y,y2c_z,rate_x,rate_y,rate_z,status,locked\n";
constexpr std::string_view kAttitudeHeader =
    "t,roll_err_deg,pitch_err_deg,heading_err_deg,angle_err_deg,"
    "raw_roll_err_deg,raw_pitch_err_deg,raw_heading_err_deg,raw_angle_err_deg,"
    "fixed_roll_err_deg,fixed_pitch_err_deg,fixed_heading_err_deg,fixed_angle_err_deg,"
    "accumulated_err_deg,raw_accumulated_err_deg,fixed_accumulated_err_deg\n";

// a CSV line under construction: fixed-decimal numbers, NaN as an empty field
class Line {
 public:
  void first(double v, int decimals) { number(v, decimals); }
  void next(double v, int decimals) {
    *p_++ = ',';
    number(v, decimals);
  }
  void next_int(long long v) {
    *p_++ = ',';
    p_ = io::write_fixed(p_, static_cast<double>(v), 0);
  }
  void next_text(std::string_view t) {
    *p_++ = ',';
    p_ = std::copy(t.begin(), t.end(), p_);
  }
  void end_into(io::OutputFile& f) {
    *p_++ = '\n';
    f.write(std::string_view(buf_, static_cast<std::size_t>(p_ - buf_)));
    p_ = buf_;
  }

 private:
  void number(double v, int decimals) {
    if (std::isfinite(v)) p_ = io::write_fixed(p_, v, decimals);
  }
  char buf_[64 * 340];  // room for 64 numbers of any size
  char* p_ = buf_;
};

// corrected.csv rows of one block, formatted into the file's buffer (runs on the writer thread)
void format_corrected(io::OutputFile& f, const std::vector<EstimateFiles::CorrectedRow>& rows) {
  std::string& out = f.buffer();
  char num[340];
  for (const auto& r : rows) {
    out.append(num, io::write_fixed(num, r.v[0], 6));
    for (int i = 1; i < 10; ++i) {
      out.push_back(',');
      if (std::isfinite(r.v[i])) out.append(num, io::write_fixed(num, r.v[i], 7));
    }
    out.push_back(',');
    out.append(est::to_string(r.status));
    out.append(r.locked ? ",1" : ",0");
    out.append(r.smoothed ? ",1\n" : "\n");
    f.maybe_drain();
  }
}

using report::json_number;
using report::json_string;

const char* reference_verdict_key(est::RefFitVerdict v) {
  switch (v) {
    case est::RefFitVerdict::kNotChecked: return "not_checked";
    case est::RefFitVerdict::kFits: return "fits";
    case est::RefFitVerdict::kOtherConvention: return "other_convention";
    case est::RefFitVerdict::kNoFit: return "no_fit";
  }
  return "?";
}

std::string json_vec(const est::Vector6d& v) {
  return fmt::format("[{}, {}, {}, {}, {}, {}]", json_number(v[0]), json_number(v[1]), json_number(v[2]),
                     json_number(v[3]), json_number(v[4]), json_number(v[5]));
}

// "figures": what --plot drew, and why a figure was left out
std::string json_figures(const std::vector<FigureOutcome>& figures) {
  std::string o = "[";
  for (std::size_t i = 0; i < figures.size(); ++i) {
    const auto& f = figures[i];
    o += fmt::format("{}{{\"name\": {}, \"written\": {}, \"reason\": {}}}", i ? ", " : "", json_string(f.stem),
                     f.written ? "true" : "false", f.written ? "null" : json_string(f.reason));
  }
  return o + "]";
}

}  // namespace

EstimateFiles::EstimateFiles(const fs::path& dir, const EstimateFilesOptions& opt)
    : opt_(opt), estimate_(dir / "estimate.csv"), attitude_(dir / "attitude.csv"), progress_("estimate") {
  if (opt_.corrected) {
    corrected_.emplace(dir / "corrected.csv");
    corrected_->write(kCorrectedHeader.substr(0, kCorrectedHeader.size() - 1));
    corrected_->write(opt_.smoothed ? ",smoothed\n" : "\n");
    corrected_writer_ = std::make_unique<io::BackgroundWriter<CorrectedRow>>(
        [this](const std::vector<CorrectedRow>& rows) { format_corrected(*corrected_, rows); });
  }
  estimate_.write(std::string(kEstimateColumns));
  estimate_.write(opt_.truth ? "," + std::string(kEstimateTruthColumns) + "\n" : std::string("\n"));
  attitude_.write(kAttitudeHeader);
}

// the writer thread stops before the file it writes is discarded
EstimateFiles::~EstimateFiles() { corrected_writer_.reset(); }

void EstimateFiles::on_smoothed_sample(const Sample& s, const est::SampleOutput& o, bool locked) {
  if (!corrected_writer_) return;
  corrected_writer_->push(CorrectedRow{{s.t_s, o.y1c_dps[0], o.y1c_dps[1], o.y1c_dps[2], o.y2c_dps[0], o.y2c_dps[1],
                                        o.y2c_dps[2], o.rate_body_dps[0], o.rate_body_dps[1], o.rate_body_dps[2]},
                                       o.status, locked, true});
}

void EstimateFiles::on_sample(const Sample& s, const est::SampleOutput& o, bool locked) {
  if (corrected_writer_ && !opt_.smoothed) {
    CorrectedRow r{{s.t_s, o.y1c_dps[0], o.y1c_dps[1], o.y1c_dps[2], o.y2c_dps[0], o.y2c_dps[1], o.y2c_dps[2],
                    o.rate_body_dps[0], o.rate_body_dps[1], o.rate_body_dps[2]},
                   o.status, locked, false};
    corrected_writer_->push(r);
  }
  if (opt_.keep_series) series_.add(s, o);
  if ((++samples_ & 8191u) == 0 && std::isfinite(opt_.t_end_s) && opt_.t_end_s > 0) {
    progress_.update(std::min(1.0, s.t_s / opt_.t_end_s));
  }
}

void EstimateFiles::on_update(const est::UpdateRecord& r, const est::Matrix6d&, const Sample& s, bool locked) {
  Line l;
  l.first(r.t_s, 6);
  for (int i = 0; i < 6; ++i) l.next(r.bias_dps[i], 9);
  for (int i = 0; i < 6; ++i) l.next(r.sigma_dps[i], 9);
  l.next(r.nis, 6);
  l.next(r.nis_gate, 6);
  l.next_int(r.dim);
  l.next_int(static_cast<long long>(r.samples));
  l.next(r.plat1_deg, 3);
  l.next(r.plat2_deg, 3);
  l.next_int(r.accepted ? 1 : 0);
  l.next_int(locked ? 1 : 0);
  if (opt_.truth) {
    for (int i = 0; i < 3; ++i) l.next(s.true_bias1_dps[i], 9);
    for (int i = 0; i < 3; ++i) l.next(s.true_bias2_dps[i], 9);
  }
  l.end_into(estimate_);
  if (opt_.keep_series) series_.add_update(r, s);
}

void EstimateFiles::on_attitude(const est::AttitudePoint& p) {
  Line l;
  l.first(p.t_s, 6);
  for (const est::AttitudeError* e : {&p.corrected, &p.raw, &p.fixed}) {
    l.next(e->roll_deg, 6);
    l.next(e->pitch_deg, 6);
    l.next(e->heading_deg, 6);
    l.next(e->angle_deg, 6);
  }
  l.next(p.corrected_accumulated_deg, 6);
  l.next(p.raw_accumulated_deg, 6);
  l.next(p.fixed_accumulated_deg, 6);
  l.end_into(attitude_);
}

void EstimateFiles::commit() {
  if (corrected_writer_) {
    corrected_writer_->finish();
    corrected_writer_.reset();
    corrected_->commit();
  }
  estimate_.commit();
  attitude_.commit();
  progress_.done(fmt::format("{} rows", samples_));
}

namespace {

// one pass's health in the model choice: its verdict, rejected fraction and NIS mean
std::string pass_health_json(const est::HealthReport& h) {
  return fmt::format("{{\"health_verdict\": \"{}\", \"rejected_fraction\": {}, \"nis_mean\": {}}}", est::to_string(h.verdict),
                     json_number(h.rejected_fraction), json_number(h.nis_mean));
}

// "self_calibration_choice": how the model was chosen (docs/estimator.md section 1i)
std::string selfcal_choice_json(const SelfcalChoice& c) {
  const bool ran = c.tried && c.error.empty();
  return fmt::format("  \"self_calibration_choice\": {{\"mode\": \"{}\", \"tried\": {}, \"used\": {}, "
                     "\"interrupted\": {}, \"error\": {}, \"called_for_by\": {}, \"six_state\": {}, "
                     "\"self_calibrating\": {}}}",
                     est::to_string(c.mode), c.tried ? "true" : "false", c.used ? "true" : "false",
                     c.interrupted ? "true" : "false", c.error.empty() ? std::string("null") : json_string(c.error),
                     c.tried ? fmt::format("\"{}\"", cause_key(c.cause)) : std::string("null"),
                     c.tried ? pass_health_json(c.six_state) : std::string("null"),
                     ran ? pass_health_json(c.selfcal) : std::string("null"));
}

}  // namespace

void write_estimate_summary(const fs::path& path, const SummaryContext& ctx, const est::EstimateSummary& s) {
  std::string o = "{\n";
  const auto add = [&o]<class... Args>(fmt::format_string<Args...> f, Args&&... args) {
    fmt::format_to(std::back_inserter(o), f, std::forward<Args>(args)...);
  };
  add("  \"complete\": {},\n", ctx.complete ? "true" : "false");
  add("  \"stopped_at_t_s\": {},\n", ctx.complete ? "null" : json_number(ctx.stopped_at_t_s));
  // corrected.csv from the smoother (--smooth) to the end: true; asked for but stopped: false
  add("  \"smoothed\": {},\n", ctx.smooth_requested ? (ctx.smoothed ? "true" : "false") : "null");
  add("  \"log\": {},\n", json_string(ctx.log_path));
  add("  \"mode\": \"{}\",\n", ctx.mode == est::FilterMode::kPaper ? "paper" : "general");
  add("  \"rows\": {},\n  \"rows_missing_gyro\": {},\n", s.rows, s.rows_missing_gyro);
  add("  \"log_complete\": {},\n", s.log_complete ? "true" : "false");
  add("  \"t_first_s\": {}, \"t_last_s\": {},\n", json_number(s.t_first_s), json_number(s.t_last_s));
  add("  \"updates\": {}, \"rejected\": {}, \"standstills_too_short\": {}, \"schedule_mismatches\": {}, "
      "\"rest_angle_mismatches\": {},\n",
      s.counters.updates, s.counters.rejected, s.counters.standstills_too_short, s.counters.schedule_mismatches,
      s.counters.rest_angle_mismatches);
  add("  \"final_bias_dps\": {},\n", json_vec(s.bias_dps));
  add("  \"final_sigma_dps\": {},\n", json_vec(s.sigma_dps));
  add("  \"temperature_states\": {{\"enabled\": {}, \"reference_degc\": [{}, {}], \"coef_dps_per_degc\": {}, "
      "\"sigma_dps_per_degc\": {}}},\n",
      s.temp_states ? "true" : "false", json_number(s.temp_ref_c[0]), json_number(s.temp_ref_c[1]),
      json_vec(s.temp_coef_dps_per_degc), json_vec(s.temp_coef_sigma_dps_per_degc));
  // row-major 3x3 per sensor
  const auto mat = [](const Eigen::Matrix3d& m) {
    return fmt::format("[[{}, {}, {}], [{}, {}, {}], [{}, {}, {}]]", json_number(m(0, 0)), json_number(m(0, 1)),
                       json_number(m(0, 2)), json_number(m(1, 0)), json_number(m(1, 1)), json_number(m(1, 2)),
                       json_number(m(2, 0)), json_number(m(2, 1)), json_number(m(2, 2)));
  };
  add("  \"self_calibration\": {{\"enabled\": {}, \"gravity_source\": \"{}\", \"correction_sigma_dps\": {}, "
      "\"g_sensitivity_dps_per_g\": [{}, {}], \"g_sensitivity_sigma_dps_per_g\": [{}, {}], "
      "\"scale_misalign_states\": {}, \"scale_misalign_frac\": [{}, {}], \"scale_misalign_sigma_frac\": [{}, {}],\n"
      "    \"end_stop_states\": {}, \"end_stop_deg\": [{}, {}, {}, {}], \"end_stop_sigma_deg\": [{}, {}, {}, {}]}},\n",
      s.gsens_states ? "true" : "false", est::to_string(s.gravity_source), json_vec(s.correction_sigma_dps),
      mat(s.gsens_dps_per_g[0]),
      mat(s.gsens_dps_per_g[1]), mat(s.gsens_sigma_dps_per_g[0]), mat(s.gsens_sigma_dps_per_g[1]),
      s.scale_states ? "true" : "false", mat(s.scale_misalign_frac[0]), mat(s.scale_misalign_frac[1]),
      mat(s.scale_misalign_sigma_frac[0]), mat(s.scale_misalign_sigma_frac[1]), s.stop_states ? "true" : "false",
      json_number(s.stop_angle_deg[0]), json_number(s.stop_angle_deg[1]), json_number(s.stop_angle_deg[2]),
      json_number(s.stop_angle_deg[3]), json_number(s.stop_angle_sigma_deg[0]), json_number(s.stop_angle_sigma_deg[1]),
      json_number(s.stop_angle_sigma_deg[2]), json_number(s.stop_angle_sigma_deg[3]));
  if (ctx.selfcal_choice != nullptr) add("{},\n", selfcal_choice_json(*ctx.selfcal_choice));
  add("  \"box_dwells\": {{\"updates\": {}, \"rejected\": {}, \"refused_moving\": {}, \"refused_turning\": {}}},\n",
      s.counters.box_dwell_updates, s.counters.box_dwell_rejected, s.counters.box_dwell_moving,
      s.counters.box_dwell_turned);
  const std::uint64_t flips_ok = s.counters.flip_updates - s.counters.flip_rejected;
  add("  \"flips\": {{\"updates\": {}, \"rejected\": {}, \"nis_mean\": {}, \"skipped_clipped\": {}}},\n",
      s.counters.flip_updates, s.counters.flip_rejected,
      json_number(flips_ok > 0 ? s.counters.flip_nis_sum / double(flips_ok) : kNaN), s.counters.flip_clipped);
  add("  \"locked_from_t_s\": {}, \"rows_locked\": {},\n", json_number(s.locked_from_t_s), s.samples_locked);
  add("  \"attitude_start_s\": {}, \"attitude_withheld_from_s\": {},\n", json_number(s.attitude_start_s),
      json_number(s.attitude_withheld_from_s));
  add("  \"box_motion_at_rest\": {{\"ref_rate_dps\": {}, \"quiet_ref_rate_dps\": {}, \"fused_rate_change_dps\": {}, "
      "\"standstills\": {}}},\n",
      json_number(s.box_motion.ref_rate_dps), json_number(s.box_motion.quiet_ref_rate_dps),
      json_number(s.box_motion.gyro_change_dps), s.box_motion.standstills);
  add("  \"reference_check\": {{\"result\": {}, \"turning_windows\": {}, \"misfit_as_written\": {}, "
      "\"best_fit\": {}, \"best_misfit\": {}}},\n",
      json_string(reference_verdict_key(s.reference.verdict)), s.reference.windows,
      json_number(s.reference.windows > 0 ? s.reference.misfit[0] : kNaN),
      json_string(est::to_string(s.reference.best)),
      json_number(s.reference.windows > 0 ? s.reference.misfit[static_cast<std::size_t>(s.reference.best)] : kNaN));
  add("  \"attitude_drift_deg_per_h\": {{\"with_driftless\": {}, \"bias_fixed_at_start\": {}, "
      "\"without_driftless\": {}}},\n",
      json_number(s.drift_corrected_deg_per_h), json_number(s.drift_fixed_deg_per_h),
      json_number(s.drift_raw_deg_per_h));
  add("  \"final_attitude_error_deg\": {{\"with_driftless\": {}, \"bias_fixed_at_start\": {}, "
      "\"without_driftless\": {}}},\n",
      json_number(s.final_corrected.angle_deg), json_number(s.final_fixed.angle_deg),
      json_number(s.final_raw.angle_deg));
  add("  \"fixed_bias_dps\": {},\n", json_vec(s.fixed_bias_dps));
  o += "  \"relocks\": [";
  for (std::size_t i = 0; i < s.relocks.size(); ++i) {
    add("{}{{\"t_s\": {}, \"nis\": {}, \"locked_again_t_s\": {}}}", i ? ", " : "", json_number(s.relocks[i].t_s),
        json_number(s.relocks[i].nis), json_number(s.relocks[i].locked_again_t_s));
  }
  o += "],\n";
  o += "  \"lock_losses\": [";
  for (std::size_t i = 0; i < s.lock_losses.size(); ++i) {
    const est::LockLoss& l = s.lock_losses[i];
    add("{}{{\"t_s\": {}, \"sigma_dps\": {}, \"relock\": {}, \"locked_again_t_s\": {}}}", i ? ", " : "",
        json_number(l.t_s), json_number(l.sigma_dps), l.relock ? "true" : "false", json_number(l.locked_again_t_s));
  }
  o += "],\n";
  if (s.truth.available) {
    const auto& t = s.truth;
    o += "  \"truth\": {\n";
    add("    \"updates_evaluated\": {},\n", t.updates);
    add("    \"bias_error_rms_dps\": {},\n", json_number(t.bias_error_rms_dps));
    add("    \"bias_error_rms_second_half_dps\": {},\n", json_number(t.bias_error_rms_second_half_dps));
    add("    \"final_bias_error_dps\": {},\n", json_vec(t.final_error_dps));
    add("    \"within_3sigma_fraction\": {},\n", json_number(t.within_3sigma_fraction));
    add("    \"nees\": {{\"dof\": 6, \"mean\": {}, \"mean_band_95\": [{}, {}], \"single_band_95\": [{}, {}], "
        "\"fraction_in_single_band\": {}}}\n",
        json_number(t.nees_mean), json_number(t.nees_mean_band_lo), json_number(t.nees_mean_band_hi),
        json_number(t.nees_band_lo), json_number(t.nees_band_hi), json_number(t.nees_fraction_in_band));
    o += "  },\n";
  }
  add("  \"bias_error_rms_dps\": {},\n", json_number(s.truth.bias_error_rms_dps));
  if (ctx.config != nullptr) add("{},\n", health_json(s.health, *ctx.config));
  add("  \"tune\": {},\n", tune_json(ctx.tune));
  if (ctx.figures != nullptr) add("  \"figures\": {},\n", json_figures(*ctx.figures));
  o += "  \"warnings\": [";
  for (std::size_t i = 0; i < s.warnings.size(); ++i) add("{}{}", i ? ", " : "", json_string(s.warnings[i]));
  o += "]\n}\n";
  io::write_file(path, o);
}

}  // namespace driftless::cli
