// Rig plan: parsing, the standard procedure, and cutting a log into fit segments with checks.
#include "calibration/rig_plan.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>

#include <fmt/core.h>

#include "estimator/geometry.hpp"
#include "estimator/output_file.hpp"
#include "twin/yaml_doc.hpp"

namespace driftless::calib {
namespace {

std::string vtext(const Eigen::Vector3d& v, int prec = 3) {
  return fmt::format("[{:.{}f}, {:.{}f}, {:.{}f}]", v.x(), prec, v.y(), prec, v.z(), prec);
}

double angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const double c = a.normalized().dot(b.normalized());
  return std::acos(std::clamp(c, -1.0, 1.0)) * kDegPerRad;
}

}  // namespace

Eigen::Vector3d orientation_axis(const std::string& orientation) {
  if (orientation == "XY") return Eigen::Vector3d::UnitZ();
  if (orientation == "YZ") return Eigen::Vector3d::UnitX();
  if (orientation == "XZ") return Eigen::Vector3d::UnitY();
  throw std::invalid_argument("unknown box orientation '" + orientation +
                              "' (expected XY, YZ, XZ, or custom with axis_box)");
}

Eigen::Quaterniond orientation_mount(const Eigen::Vector3d& axis_box) {
  // the rotation taking the box axis to ENU up
  return Eigen::Quaterniond::FromTwoVectors(axis_box.normalized(), Eigen::Vector3d::UnitZ());
}

double PlanSegment::sign_at(double t_s) const {
  if (!(t_s >= t_start_s && t_s < t_end_s)) return 0.0;
  const auto k = static_cast<long long>(std::floor((t_s - t_start_s) / half_period_s));
  return (k % 2 == 0) ? first_sign : -first_sign;
}

bool PlanSegment::on_plateau(double t_s) const {
  if (!(t_s >= t_start_s && t_s < t_end_s)) return false;
  const double since = std::fmod(t_s - t_start_s, half_period_s);
  return since >= settle_s;
}

void RigPlan::validate() const {
  if (!(gyro_full_scale_dps > 0.0)) throw std::invalid_argument("rig plan: gyro_full_scale_dps must be > 0");
  if (!(max_rate_fraction > 0.0 && max_rate_fraction <= 1.0))
    throw std::invalid_argument("rig plan: max_rate_fraction must be in (0, 1]");
  if (segments.empty()) throw std::invalid_argument("rig plan: no segments");
  std::set<std::string> names;
  const PlanSegment* prev = nullptr;
  for (const auto& s : segments) {
    const std::string w = "rig plan: segment '" + s.name + "': ";
    if (s.name.empty()) throw std::invalid_argument("rig plan: a segment has no name");
    if (!names.insert(s.name).second) throw std::invalid_argument(w + "name used twice");
    if (s.position(0) < 0 || s.position(1) < 0)
      throw std::invalid_argument(w + "plat1_deg and plat2_deg must be -90 or +90 (end stops), got " +
                                  fmt::format("{} and {}", s.plat1_deg, s.plat2_deg));
    if (std::abs(s.axis_box.norm() - 1.0) > 1e-9)
      throw std::invalid_argument(w + "axis_box must be a unit vector");
    if (!(s.t_end_s > s.t_start_s)) throw std::invalid_argument(w + "t_end_s must exceed t_start_s");
    if (!(s.rate_dps > 0.0)) throw std::invalid_argument(w + "rate_dps must be > 0");
    if (s.rate_dps > max_rate_fraction * gyro_full_scale_dps) {
      throw std::invalid_argument(fmt::format(
          "{}the rate table's {} deg/s saturates the gyro: full scale is +-{} deg/s and a "
          "calibration needs headroom for scale, misalignment and bias (at most {:.0f} % = {} "
          "deg/s); lower rate_dps or raise gyro_full_scale_dps (FS_SEL)",
          w, s.rate_dps, gyro_full_scale_dps, 100 * max_rate_fraction,
          max_rate_fraction * gyro_full_scale_dps));
    }
    if (!(s.half_period_s > 0.0)) throw std::invalid_argument(w + "half_period_s must be > 0");
    if (!(s.settle_s >= 0.0 && s.settle_s < 0.8 * s.half_period_s))
      throw std::invalid_argument(w + "settle_s must be in [0, 0.8 half_period_s)");
    if (s.first_sign != 1.0 && s.first_sign != -1.0)
      throw std::invalid_argument(w + "first_sign must be +1 or -1");
    if (s.t_end_s - s.t_start_s < 2.0 * s.half_period_s)
      throw std::invalid_argument(w + "shorter than one full period (needs both +rate and -rate)");
    if (prev && s.t_start_s < prev->t_end_s)
      throw std::invalid_argument(w + "starts before segment '" + prev->name +
                                  "' ends (segments must be in time order, not overlapping)");
    prev = &s;
  }
}

void ProcedureParams::validate() const {
  if (!(rate_dps > 0 && segment_s > 0 && half_period_s > 0 && settle_s >= 0 && gap_s >= 0 &&
        start_s >= 0 && gyro_full_scale_dps > 0))
    throw std::invalid_argument("calibration procedure: rate_dps, segment_s, half_period_s and "
                                "gyro_full_scale_dps must be > 0; settle_s, gap_s, start_s >= 0");
  if (orientations.empty()) throw std::invalid_argument("calibration procedure: no orientations");
  for (const auto& o : orientations) orientation_axis(o);
}

RigPlan standard_plan(const ProcedureParams& p) {
  p.validate();
  RigPlan plan;
  plan.gyro_full_scale_dps = p.gyro_full_scale_dps;
  double t = p.start_s;
  for (double stop : {-90.0, 90.0}) {
    for (const auto& o : p.orientations) {
      PlanSegment s;
      s.orientation = o;
      s.name = o + "@" + (stop > 0 ? "+90" : "-90");
      s.axis_box = orientation_axis(o);
      s.plat1_deg = s.plat2_deg = stop;
      s.t_start_s = t;
      s.t_end_s = t + p.segment_s;
      s.rate_dps = p.rate_dps;
      s.half_period_s = p.half_period_s;
      s.settle_s = p.settle_s;
      plan.segments.push_back(s);
      t = s.t_end_s + p.gap_s;
    }
  }
  plan.validate();
  return plan;
}

namespace {

// ---- the plan file: one table per block drives parse, allowed keys and emit ----

bool is_custom(const PlanSegment& s) { return s.orientation == "custom"; }

const fields::Table<PlanSegment>& segment_table() {
  using S = PlanSegment;
  static const fields::Table<S> t = [] {
    fields::Table<S> rows = {
        fields::text<S>("name", &S::name),
        fields::text<S>("orientation", &S::orientation),
        fields::written_if<S>(fields::vector<S>("axis_box", "", &S::axis_box), is_custom),
    };
    append_span_rows(rows, [](auto& s) -> auto& { return s; });
    rows.push_back(fields::number<S>("half_period", "s", &S::half_period_s));
    rows.push_back(fields::number<S>("first_sign", "", &S::first_sign));
    rows.push_back(fields::number<S>("settle", "s", &S::settle_s));
    return rows;
  }();
  return t;
}

// `defaults:` holds the segment keys every segment may leave out
const fields::Table<PlanSegment>& defaults_table() {
  using S = PlanSegment;
  static const fields::Table<S> t = {
      fields::number<S>("rate", "dps", &S::rate_dps),
      fields::number<S>("half_period", "s", &S::half_period_s),
      fields::number<S>("settle", "s", &S::settle_s),
  };
  return t;
}

// the whole file; segments are read after the map, so `defaults:` may stand anywhere
struct PlanDoc {
  std::string format = kRigPlanFormat;
  RigPlan plan;
  PlanSegment defaults;
  fields::Node segments;
};

const fields::Table<PlanDoc>& plan_table() {
  using D = PlanDoc;
  static const fields::Table<D> t = {
      fields::text<D>("format", &D::format),
      fields::number<D>("gyro_full_scale", "dps", [](auto& d) -> auto& { return d.plan.gyro_full_scale_dps; }),
      fields::number<D>("max_rate_fraction", "", [](auto& d) -> auto& { return d.plan.max_rate_fraction; }),
      fields::written_if<D>(fields::number<D>("latitude", "deg", [](auto& d) -> auto& { return d.plan.latitude_deg; }),
                            [](const D& d) { return std::isfinite(d.plan.latitude_deg); }),
      fields::custom<D>(
          "defaults", "",
          [](D& d, const fields::Node& n, const fields::Reading& r) { fields::read_block(defaults_table(), d.defaults, n, r.ctx); },
          [](const D&) -> std::optional<fields::Node> { return std::nullopt; }),
      fields::custom<D>(
          "segments", "", [](D& d, const fields::Node& n, const fields::Reading&) { d.segments = n; },
          [](const D& d) -> std::optional<fields::Node> {
            std::vector<fields::Node> items;
            for (const auto& s : d.plan.segments) items.push_back(fields::write_block(segment_table(), s, true));
            return fields::Node::list(std::move(items), false);
          }),
  };
  return t;
}

// one segment: the defaults, then its keys; a named orientation gives the table axis, `custom`
// takes axis_box (normalised)
PlanSegment read_segment(const fields::Node& n, const fields::Context& ctx, const PlanSegment& defaults) {
  PlanSegment seg = defaults;
  const auto given = fields::read_block(segment_table(), seg, n, ctx);
  fields::require(segment_table(), given, n, ctx,
                  {"name", "orientation", "plat1_deg", "plat2_deg", "t_start_s", "t_end_s"});
  const fields::Node* axis = n.find("axis_box");
  if (is_custom(seg)) {
    if (axis == nullptr) ctx.fail(n, ctx.key("axis_box"), "missing (orientation: custom needs axis_box [x, y, z])");
    if (seg.axis_box.norm() < 1e-6) ctx.fail(*axis, ctx.key("axis_box"), "zero vector");
    seg.axis_box.normalize();
    return seg;
  }
  try {
    seg.axis_box = orientation_axis(seg.orientation);
  } catch (const std::invalid_argument& e) {
    ctx.fail(*n.find("orientation"), ctx.key("orientation"), e.what());
  }
  if (axis != nullptr) ctx.fail(*axis, ctx.key("axis_box"), "only with orientation: custom");
  return seg;
}

}  // namespace

RigPlan read_rig_plan(const fields::Node& root, const std::string& file) {
  if (!root.is_map()) throw InputError(file, root.line, "", "a rig plan must be a YAML map (docs/calibration.md)");
  const fields::Context ctx{file, ""};
  PlanDoc doc;
  const auto given = fields::read_block(plan_table(), doc, root, ctx);
  if (doc.format != kRigPlanFormat)
    ctx.fail(*root.find("format"), "format", std::string("expected '") + kRigPlanFormat + "', got '" + doc.format + "'");
  fields::require(plan_table(), given, root, ctx, {"segments"});
  if (!doc.segments.is_list()) ctx.fail(doc.segments, "segments", "expected a list of segments");
  for (std::size_t i = 0; i < doc.segments.items.size(); ++i) {
    const fields::Context seg_ctx{file, "segments[" + std::to_string(i) + "]"};
    doc.plan.segments.push_back(read_segment(doc.segments.items[i], seg_ctx, doc.defaults));
  }
  with_location(file, 0, "", [&] { doc.plan.validate(); });
  return doc.plan;
}

RigPlan parse_rig_plan(const std::string& yaml_text, const std::string& file) {
  return read_rig_plan(twin::parse_yaml(yaml_text, file), file);
}

RigPlan load_rig_plan(const std::filesystem::path& path) {
  return read_rig_plan(twin::load_yaml_file(path), path.string());
}

std::string rig_plan_yaml(const RigPlan& plan) {
  PlanDoc doc;
  doc.plan = plan;
  return twin::to_yaml(fields::write_block(plan_table(), doc),
                       "rig plan for driftless calibrate --plan (docs/calibration.md)") + "\n";
}

void save_rig_plan(const std::filesystem::path& path, const RigPlan& plan) { io::write_file(path, rig_plan_yaml(plan)); }

namespace {

// what extract_segments knows about the whole log while it walks the segments
struct ExtractContext {
  const std::vector<Sample>& log;
  std::string log_name;
  std::string mismatch;  // message prefix: "plan does not match the log <name>: "
  Eigen::Vector3d hinge[2];
  Eigen::Vector3d w_earth_enu_dps = Eigen::Vector3d::Zero();
  double fs_sat_dps = 0.0;
  double temp_sum[2] = {0, 0};
  std::size_t temp_n[2] = {0, 0};
};

// one segment's running sums besides its samples
struct SegmentSums {
  Eigen::Vector3d turn_sum = Eigen::Vector3d::Zero();  // the table's turn from ref_q, deg/s
  double turn_n = 0;
  Eigen::Vector3d f_sum[2] = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  double f_n[2] = {0, 0}, tc_sum[2] = {0, 0}, tc_n[2] = {0, 0};
};

// the sensor's nominal response to the table's rate: R_i(p)^T a rate, sensor axes
Eigen::Vector3d nominal_response_dps(const ExtractContext& c, const PlanSegment& ps, int i, int pos) {
  return geo::rot_about_axis_deg(c.hinge[i], est::position_deg(pos)).transpose() * ps.axis_box * ps.rate_dps;
}

// the platform angles as the log knows them must sit at the planned end stops; the gyros must not
// reach their full scale
void check_row(const ExtractContext& c, const PlanSegment& ps, const std::string& seg_where, const Sample& s) {
  const double plat[2] = {s.plat1_deg, s.plat2_deg};
  const double want[2] = {ps.plat1_deg, ps.plat2_deg};
  for (int i = 0; i < 2; ++i) {
    if (!std::isfinite(plat[i]) || std::abs(plat[i] - want[i]) > 2.0) {
      throw std::invalid_argument(fmt::format(
          "{}{}: at t = {} s plat{}_deg is {} but the plan puts platform {} at {} deg", c.mismatch,
          seg_where, s.t_s, i + 1, std::isfinite(plat[i]) ? fmt::format("{}", plat[i]) : std::string("empty (moving)"),
          i + 1, want[i]));
    }
  }
  if (!s.gyros_finite()) return;
  for (int i = 0; i < 2; ++i) {
    const Eigen::Vector3d& y = i == 0 ? s.gyro1_dps : s.gyro2_dps;
    if (y.cwiseAbs().maxCoeff() >= 0.999 * c.fs_sat_dps) {
      throw std::invalid_argument(fmt::format(
          "{}: {}: gyro {} reads {} deg/s at t = {} s, at its full scale +-{} deg/s: the rate "
          "table saturates the gyro (lower rate_dps, or set gyro_full_scale_dps to the "
          "sensor's range)", c.log_name, seg_where, i + 1, vtext(y, 2), s.t_s, c.fs_sat_dps));
    }
  }
}

// one plateau sample: the fit's input, the turn ref_q shows, gravity and temperature sums
void add_plateau_sample(const ExtractContext& c, const PlanSegment& ps, const Sample& s,
                        const Sample* prev_plateau, est::CalibSegment& seg, SegmentSums& sums) {
  est::CalibSample x;
  x.t_s = s.t_s;
  x.sign = ps.sign_at(s.t_s);
  x.gyro_dps = {s.gyro1_dps, s.gyro2_dps};
  const bool q_ok = s.ref_q_wxyz.allFinite();
  if (q_ok) x.earth_rate_box_dps = s.q_enu_from_body().normalized().conjugate() * c.w_earth_enu_dps;
  // the table's turn as ref_q shows it, box axes: 2 vec(q_k^-1 q_k+1) / dt
  if (q_ok && prev_plateau && prev_plateau->ref_q_wxyz.allFinite() && ps.sign_at(prev_plateau->t_s) == x.sign) {
    const Eigen::Quaterniond dq =
        prev_plateau->q_enu_from_body().normalized().conjugate() * s.q_enu_from_body().normalized();
    sums.turn_sum += x.sign * geo::rotvec_rad(dq) * kDegPerRad / (s.t_s - prev_plateau->t_s);
    sums.turn_n += 1;
  }
  seg.samples.push_back(x);
  // gravity in sensor axes for the g-sensitivity fit
  const Eigen::Vector3d* f[2] = {&s.accel1_mps2, &s.accel2_mps2};
  const double tc[2] = {s.temp1_c, s.temp2_c};
  for (int i = 0; i < 2; ++i) {
    if (std::isfinite(tc[i])) sums.tc_sum[i] += tc[i], sums.tc_n[i] += 1;
    if (!f[i]->allFinite()) continue;
    sums.f_sum[i] += *f[i] / kStandardGravityMps2;
    sums.f_n[i] += 1;
  }
}

// the rows of one planned segment, checked against the plan
est::CalibSegment collect_segment(ExtractContext& c, const PlanSegment& ps, const std::string& seg_where,
                                  ExtractReport& rep, SegmentSums& sums) {
  est::CalibSegment seg;
  seg.name = ps.name;
  seg.orientation = ps.orientation;
  seg.pos = {ps.position(0), ps.position(1)};
  seg.axis_box = ps.axis_box;
  seg.rate_dps = ps.rate_dps;
  auto first = std::lower_bound(c.log.begin(), c.log.end(), ps.t_start_s,
                                [](const Sample& s, double t) { return s.t_s < t; });
  const Sample* prev_plateau = nullptr;
  for (auto it = first; it != c.log.end() && it->t_s < ps.t_end_s; ++it) {
    const Sample& s = *it;
    check_row(c, ps, seg_where, s);
    if (!s.gyros_finite()) {
      ++rep.rows_skipped_nan;
      prev_plateau = nullptr;
      continue;
    }
    const double temp[2] = {s.temp1_c, s.temp2_c};
    for (int i = 0; i < 2; ++i)
      if (std::isfinite(temp[i])) c.temp_sum[i] += temp[i], ++c.temp_n[i];
    if (!ps.on_plateau(s.t_s)) {
      prev_plateau = nullptr;
      continue;
    }
    add_plateau_sample(c, ps, s, prev_plateau, seg, sums);
    prev_plateau = &s;
  }
  for (int i = 0; i < 2; ++i) {
    const auto iu = static_cast<std::size_t>(i);
    const double half = 0.5 * static_cast<double>(seg.samples.size());
    if (sums.f_n[i] > half) seg.f_mean_g[iu] = sums.f_sum[i] / sums.f_n[i];
    if (sums.tc_n[i] > half) seg.temp_mean_c[iu] = sums.tc_sum[i] / sums.tc_n[i];
  }
  if (seg.samples.empty()) throw std::invalid_argument(c.mismatch + seg_where + " holds no usable plateau samples");
  return seg;
}

// the reference attitude must show the planned turn
void check_turn(const ExtractContext& c, const PlanSegment& ps, const std::string& seg_where, const SegmentSums& sums) {
  if (!(sums.turn_n > 10)) return;
  const Eigen::Vector3d turn = sums.turn_sum / sums.turn_n;
  if (angle_deg(turn, ps.axis_box) > 10.0 || std::abs(turn.norm() / ps.rate_dps - 1.0) > 0.1) {
    throw std::invalid_argument(fmt::format(
        "{}{}: the reference attitude (ref_q) shows the box turning at {:.1f} deg/s about box "
        "{}, the plan says {} deg/s about box {} (orientation {}, first_sign {:+g}); check the "
        "orientation, rate_dps, t_start_s, half_period_s and first_sign",
        c.mismatch, seg_where, turn.norm(), vtext(turn.normalized()), ps.rate_dps, vtext(ps.axis_box, 0),
        ps.orientation, ps.first_sign));
  }
}

// a clipped sensor shows a flat top below the level the turn should give: one extreme value
// repeated over much of a plateau, short of the nominal response |R_i(p)^T a| rate
void check_clipping(const ExtractContext& c, const PlanSegment& ps, const std::string& seg_where,
                    const est::CalibSegment& seg) {
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 3; ++j)
      for (double sgn : {1.0, -1.0}) {
        const double nominal = std::abs(nominal_response_dps(c, ps, i, seg.pos[i])[j]);
        double extreme = 0.0;
        std::size_t n = 0, at = 0;
        for (const auto& x : seg.samples)
          if (x.sign == sgn) extreme = std::max(extreme, std::abs(x.gyro_dps[i][j])), ++n;
        for (const auto& x : seg.samples)
          if (x.sign == sgn && std::abs(x.gyro_dps[i][j]) >= extreme - 1e-9) ++at;
        if (n > 20 && at > n / 20 && extreme > 0.5 * ps.rate_dps && extreme < 0.9 * nominal) {
          throw std::invalid_argument(fmt::format(
              "{}: {}: gyro {} axis {} sits at {:.4f} deg/s in {:.0f} % of the {} plateau: it is "
              "clipped, the rate table saturates the gyro (lower rate_dps or raise the sensor's "
              "full scale, FS_SEL)", c.log_name, seg_where, i + 1, "xyz"[j], extreme,
              100.0 * static_cast<double>(at) / static_cast<double>(n), sgn > 0 ? "+rate" : "-rate"));
        }
      }
}

// each sensor must follow the planned square wave: mean(sign y) ~ R_i(p)^T a rate
void check_square_wave(const ExtractContext& c, const PlanSegment& ps, const std::string& seg_where,
                       const est::CalibSegment& seg) {
  for (int i = 0; i < 2; ++i) {
    Eigen::Vector3d d = Eigen::Vector3d::Zero();
    for (const auto& x : seg.samples) d += x.sign * x.gyro_dps[i];
    d /= static_cast<double>(seg.samples.size());
    const Eigen::Vector3d expected = nominal_response_dps(c, ps, i, seg.pos[i]);
    if (d.norm() < 0.5 * ps.rate_dps || angle_deg(d, expected) > 30.0) {
      throw std::invalid_argument(fmt::format(
          "{}{}: sensor {}'s output does not follow the planned +-{} deg/s square wave: its mean "
          "signed response is {} deg/s, a turn about box {} with platform {} at {} should give "
          "about {} deg/s (check t_start_s, half_period_s, first_sign, the orientation and "
          "plat{}_deg)",
          c.mismatch, seg_where, i + 1, ps.rate_dps, vtext(d, 2), vtext(ps.axis_box, 0), i + 1,
          est::position_name(seg.pos[i]), vtext(expected, 1), i + 1));
    }
  }
}

}  // namespace

std::vector<est::CalibSegment> extract_segments(const std::vector<Sample>& log,
                                                const log::Metadata& meta, const RigPlan& plan,
                                                const std::string& log_name,
                                                ExtractReport* report) {
  plan.validate();
  ExtractReport rep;
  ExtractContext c{log, log_name, "plan does not match the log " + log_name + ": ",
                   {meta.hinge1_axis().normalized(), meta.hinge2_axis().normalized()}};
  if (log.empty()) throw std::invalid_argument(c.mismatch + "the log holds no samples");
  rep.sample_rate_hz = meta.sample_rate_hz();
  rep.latitude_deg = std::isfinite(plan.latitude_deg) ? plan.latitude_deg : meta.latitude_deg();
  const bool have_ref_q = std::any_of(log.begin(), log.end(), [](const Sample& s) { return s.ref_q_wxyz.allFinite(); });
  rep.earth_rate_removed = have_ref_q && std::isfinite(rep.latitude_deg);
  if (!have_ref_q) rep.notes.push_back("the log has no ref_q: the Earth rate is not removed");
  else if (!std::isfinite(rep.latitude_deg))
    rep.notes.push_back("no latitude_deg in the log or the plan: the Earth rate is not removed");
  if (rep.earth_rate_removed) c.w_earth_enu_dps = geo::earth_rate_enu_radps(rep.latitude_deg) * kDegPerRad;
  c.fs_sat_dps = plan.gyro_full_scale_dps;
  const double t_log0 = log.front().t_s, t_log1 = log.back().t_s;

  std::vector<est::CalibSegment> out;
  for (const auto& ps : plan.segments) {
    const std::string seg_where = fmt::format("segment '{}' (t = {} .. {} s)", ps.name, ps.t_start_s, ps.t_end_s);
    if (ps.t_start_s < t_log0 || ps.t_end_s > t_log1 + 0.5) {
      throw std::invalid_argument(fmt::format("{}{} lies outside the log (t = {} .. {} s)", c.mismatch,
                                              seg_where, t_log0, t_log1));
    }
    SegmentSums sums;
    est::CalibSegment seg = collect_segment(c, ps, seg_where, rep, sums);
    check_turn(c, ps, seg_where, sums);
    check_clipping(c, ps, seg_where, seg);
    check_square_wave(c, ps, seg_where, seg);
    rep.samples_used.push_back(seg.samples.size());
    out.push_back(std::move(seg));
  }
  for (int i = 0; i < 2; ++i)
    if (c.temp_n[i] > 0) rep.mean_temp_c[i] = c.temp_sum[i] / static_cast<double>(c.temp_n[i]);
  if (report) *report = rep;
  return out;
}

}  // namespace driftless::calib
