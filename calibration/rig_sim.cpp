// The simulated calibration rig on the twin's pan/tilt unit (see rig_sim.hpp).
#include "calibration/rig_sim.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>
#include <stdexcept>

#include <fmt/core.h>

#include "estimator/geometry.hpp"
#include "twin/flip_schedule.hpp"
#include "twin/motion.hpp"
#include "twin/sensor/sensor_model.hpp"
#include "twin/simulator.hpp"
#include "twin/world.hpp"
#include "twin/yaml_doc.hpp"

namespace driftless::calib {

using twin::Scenario;
using twin::World;
using twin::BoxParams;
using twin::TrapezoidProfile;
using twin::SensorParams;
using twin::SensorInstance;
using twin::Carrier;
using twin::Motion;
using twin::parse_scenario;
namespace {

// ---- the rate table: square wave with finite acceleration, closed form -----------------------

// the table rate (deg/s, signed about the segment axis) and turned angle (deg) since t_start_s
struct TableProfile {
  const PlanSegment* s;
  double a;  // deg/s^2

  double rate_at_end() const {
    const double span = s->t_end_s - s->t_start_s;
    const double k = std::ceil(span / s->half_period_s) - 1.0;
    return rate_in(static_cast<long>(k), span - k * s->half_period_s);
  }
  // rate tau seconds into half period k
  double rate_in(long k, double tau) const {
    const double R = s->rate_dps, sk = (k % 2 == 0) ? s->first_sign : -s->first_sign;
    if (k == 0) return sk * std::min(a * tau, R);
    return sk * std::min(-R + a * tau, R);
  }
  // angle turned during the first tau seconds of half period k
  double angle_in(long k, double tau) const {
    const double R = s->rate_dps, sk = (k % 2 == 0) ? s->first_sign : -s->first_sign;
    if (k == 0) {
      const double tr = R / a;
      return sk * (tau <= tr ? 0.5 * a * tau * tau : 0.5 * R * tr + R * (tau - tr));
    }
    const double tr = 2.0 * R / a;
    return sk * (tau <= tr ? -R * tau + 0.5 * a * tau * tau : R * (tau - tr));
  }
  double ramp_down_s() const { return std::abs(rate_at_end()) / a; }
  // angle (deg) at time t: ramps, plateaus, and the ramp down after t_end_s
  double angle(double t) const {
    if (t <= s->t_start_s) return 0.0;
    const double T = s->half_period_s;
    const double tt = std::min(t, s->t_end_s) - s->t_start_s;
    const long kmax = static_cast<long>(std::floor(tt / T));
    double ang = 0.0;
    for (long k = 0; k < kmax; ++k) ang += angle_in(k, T);
    ang += angle_in(kmax, tt - static_cast<double>(kmax) * T);
    if (t > s->t_end_s) {
      const double r0 = rate_at_end();
      const double td = std::min(t - s->t_end_s, ramp_down_s());
      ang += r0 * td - (r0 > 0 ? 1.0 : -1.0) * 0.5 * a * td * td;
    }
    return ang;
  }
};

double smoothstep(double x) {
  x = std::clamp(x, 0.0, 1.0);
  return x * x * x * (10.0 + x * (-15.0 + 6.0 * x));  // C2: zero rate and acceleration at the ends
}

Eigen::Quaterniond rz_deg(double deg) {
  return geo::quat_from_rotvec(Eigen::Vector3d::UnitZ() * (deg * kRadPerDeg));
}

// the pan/tilt unit as a rate table: the box mounted with the segment axis up, turned about up
class RigMotion final : public Motion {
 public:
  RigMotion(const RigPlan& plan, double accel_dps2, double remount_s)
      : plan_(plan), accel_(accel_dps2), remount_s_(remount_s) {
    for (const auto& s : plan_.segments) {
      TableProfile tp{&s, accel_};
      end_q_.push_back(rz_deg(tp.angle(s.t_end_s + tp.ramp_down_s())) * orientation_mount(s.axis_box));
      rest_s_.push_back(s.t_end_s + tp.ramp_down_s());
    }
  }
  void pose(double t, Eigen::Vector3d& p, Eigen::Quaterniond& q) const override {
    const auto& segs = plan_.segments;
    std::size_t k = 0;
    while (k + 1 < segs.size() && t >= segs[k + 1].t_start_s) ++k;
    const PlanSegment& s = segs[k];
    const TableProfile tp{&s, accel_};
    if (k == 0 && t < s.t_start_s) {
      q = orientation_mount(s.axis_box);
    } else if (t <= rest_s_[k] || k + 1 == segs.size()) {
      q = rz_deg(tp.angle(t)) * orientation_mount(s.axis_box);
    } else {
      // re-orientation to the next segment's mount, then rest
      const Eigen::Quaterniond next = orientation_mount(segs[k + 1].axis_box);
      q = end_q_[k].slerp(smoothstep((t - rest_s_[k]) / remount_s_), next);
    }
    const Eigen::Quaterniond yoke = rz_deg(0.0);
    p = World::pan_tilt_axis_enu_m() + yoke * World::box_on_tilt_head_m();
  }
  Carrier carrier() const override { return Carrier::pan_tilt; }

 private:
  RigPlan plan_;
  double accel_, remount_s_;
  std::vector<Eigen::Quaterniond> end_q_;
  std::vector<double> rest_s_;
};

// ---- the platforms: pressed onto their stops; flipped in a gap when the next segment asks ----

struct PlatformPlan {
  struct Flip {
    double t0_s;
    int sign;                // the stop it goes to, +1 / -1
    TrapezoidProfile profile;
    double known_from_s;  // the system knows the new angle again from here (at the latest)
  };
  double initial_sign = -1.0;
  std::vector<Flip> flips;
};

PlatformPlan platform_plan(const RigPlan& plan, const RigParams& rig, const BoxParams& box, int i) {
  PlatformPlan pp;
  const auto deg = [i](const PlanSegment& s) { return i == 1 ? s.plat1_deg : s.plat2_deg; };
  const double press_rad = (box.end_stop_deg + box.motor.overtravel_deg) * kRadPerDeg;
  pp.initial_sign = deg(plan.segments.front()) > 0 ? 1.0 : -1.0;
  double sign = pp.initial_sign;
  for (std::size_t k = 1; k < plan.segments.size(); ++k) {
    const double want = deg(plan.segments[k]) > 0 ? 1.0 : -1.0;
    if (want == sign) continue;
    const auto& prev = plan.segments[k - 1];
    const double t0 = prev.t_end_s + rig.remount_s + 0.5;
    TrapezoidProfile prof(t0, sign * press_rad, want * press_rad, box.motor.max_speed_dps * kRadPerDeg,
                          box.motor.max_accel_dps2 * kRadPerDeg);
    const double known = prof.end_s() + 0.5;
    if (known > plan.segments[k].t_start_s) {
      throw std::invalid_argument(fmt::format(
          "calibration: the platforms need {:.1f} s to re-orient and flip after segment '{}' but "
          "the gap is {:.1f} s; raise calibration.gap_s", known - prev.t_end_s, prev.name,
          plan.segments[k].t_start_s - prev.t_end_s));
    }
    pp.flips.push_back({t0, want > 0 ? 1 : -1, prof, known});
    sign = want;
  }
  return pp;
}

// the rig's platform commander: it starts each planned flip through the simulator's external
// flip control (twin::FlipController runs the motor profile and knows the angles from the stops)
class RigCommander {
 public:
  explicit RigCommander(const PlatformPlan (&pp)[2]) : pp_{&pp[0], &pp[1]} {}
  /// Commands every flip due before the sample at t_next_s (it starts at the next physics step,
  /// at most one sample period ahead of its planned time).
  void before_sample(twin::Simulator& sim, double t_next_s) {
    for (int i = 0; i < 2; ++i) {
      const auto& flips = pp_[i]->flips;
      for (std::size_t& k = next_[i]; k < flips.size() && flips[k].t0_s <= t_next_s; ++k) {
        sim.command_platform(i + 1, flips[k].sign);
      }
    }
  }

 private:
  const PlatformPlan* pp_[2];
  std::size_t next_[2] = {0, 0};
};

// the calibration scenario as the simulator runs it: the plan's length, the platforms pressed
// onto their end stops and known from the stops' switches (the rig plan's +-90)
Scenario rig_scenario(const Scenario& sc, const RigPlan& plan) {
  Scenario r = sc;
  r.duration_s = plan.segments.back().t_end_s + 1.0;
  r.flip_schedule.flip_angle_deg = r.model.box.end_stop_deg;
  r.platform_readback = twin::PlatformReadback::end_stops;
  return r;
}

// where the platforms really rest during the fit's plateaus, and the sensors' mean temperature
struct RigTruthSums {
  double rest_sum[2][2] = {{0, 0}, {0, 0}}, rest_n[2][2] = {{0, 0}, {0, 0}}, temp_sum[2] = {0, 0};
  double samples = 0;

  void add(const RigPlan& plan, const Sample& s) {
    const double plat_deg[2] = {s.true_plat1_deg, s.true_plat2_deg};
    for (const auto& seg : plan.segments) {
      if (!seg.on_plateau(s.t_s)) continue;
      for (int i = 0; i < 2; ++i) {
        rest_sum[i][seg.position(i)] += plat_deg[i];
        rest_n[i][seg.position(i)] += 1;
      }
    }
    temp_sum[0] += s.temp1_c;
    temp_sum[1] += s.temp2_c;
    samples += 1;
  }
};

// the true M: sensor calibration C from the realised model, T from the rest angles (M^-1 = C T^T)
void true_matrices(const twin::Simulator& sim, const BoxParams& box, const RigTruthSums& sums, RigRun& run) {
  const Eigen::Vector3d hinge[2] = {box.hinge_axis(1), box.hinge_axis(2)};
  for (int i = 0; i < 2; ++i) {
    const SensorInstance& inst = sim.sensor(i + 1).instance();
    const SensorParams& p = sim.sensor(i + 1).params();
    const double dT = sums.temp_sum[i] / sums.samples - p.temperature.reference_degc;
    const Eigen::Vector3d k = inst.scale + inst.scale_tc_per_degc * dT;
    const Eigen::Matrix3d C = inst.misalignment * k.asDiagonal() * inst.R_sensor_from_nominal;
    for (int pos = 0; pos < 2; ++pos) {
      run.rest_angle_deg[i][pos] = sums.rest_n[i][pos] > 0 ? sums.rest_sum[i][pos] / sums.rest_n[i][pos] : kNaN;
      run.true_M.M(i, pos) =
          (C * geo::rot_about_axis_deg(hinge[i], run.rest_angle_deg[i][pos]).transpose()).inverse();
    }
  }
}

// ---- scenario file: a normal scenario plus a `calibration:` block -----------------------------

// the calibration: block, one table (docs/calibration.md)
const fields::Table<RigParams>& rig_table() {
  using R = RigParams;
  const auto proc = [](double ProcedureParams::*m) { return [m](auto& r) -> auto& { return r.procedure.*m; }; };
  static const fields::Table<R> t = {
      fields::number<R>("rate", "dps", proc(&ProcedureParams::rate_dps)),
      fields::number<R>("segment", "s", proc(&ProcedureParams::segment_s)),
      fields::number<R>("half_period", "s", proc(&ProcedureParams::half_period_s)),
      fields::number<R>("settle", "s", proc(&ProcedureParams::settle_s)),
      fields::number<R>("gap", "s", proc(&ProcedureParams::gap_s)),
      fields::number<R>("start", "s", proc(&ProcedureParams::start_s)),
      fields::text_list<R>("orientations", [](auto& r) -> auto& { return r.procedure.orientations; }),
      fields::number<R>("gyro_full_scale", "dps", proc(&ProcedureParams::gyro_full_scale_dps)),
      fields::number<R>("table_accel", "dps2", &R::table_accel_dps2),
      fields::number<R>("remount", "s", &R::remount_s),
      fields::text<R>("method", &R::method),
  };
  return t;
}

RigParams parse_rig(const fields::Node& n, const std::string& file) {
  RigParams r;
  r.procedure.gap_s = 8.0;
  fields::read_block(rig_table(), r, n, fields::Context{file, "calibration"});
  with_location(file, n.line, "calibration", [&] { r.validate(); });
  return r;
}

}  // namespace

void RigParams::validate() const {
  procedure.validate();
  if (!(table_accel_dps2 > 0.0)) throw std::invalid_argument("table_accel_dps2 must be > 0 deg/s^2");
  const double ramp_s = 2.0 * procedure.rate_dps / table_accel_dps2;
  if (procedure.settle_s < ramp_s) {
    throw std::invalid_argument(fmt::format(
        "settle_s = {} s is shorter than the table's reversal ({} s at {} deg/s^2): samples of the "
        "reversal would enter the fit", procedure.settle_s, ramp_s, table_accel_dps2));
  }
  if (!(remount_s > 0.0) || remount_s + 0.5 > procedure.gap_s)
    throw std::invalid_argument("remount_s must be > 0 and at least 0.5 s shorter than gap_s");
  if (method != "least_squares" && method != "top_to_top")
    throw std::invalid_argument("method must be least_squares or top_to_top, got '" + method + "'");
}

CalibScenario load_calib_scenario(const std::filesystem::path& path) {
  const std::string file = path.string();
  const std::string text = twin::read_yaml_text(path);
  const fields::Node root = twin::parse_yaml(text, file);
  const fields::Node* block = root.is_map() ? root.find("calibration") : nullptr;
  if (block == nullptr) {
    throw InputError(file, 0, "", "no `calibration:` block: not a calibration scenario "
                                  "(see models/scenarios/calibration.yaml, docs/calibration.md)");
  }
  CalibScenario cs;
  cs.rig = parse_rig(*block, file);
  // hand the rest to the scenario parser with the calibration lines blanked (line numbers kept)
  std::size_t first = 0, next = SIZE_MAX;
  for (const auto& e : root.entries)
    if (e.key == "calibration") first = e.line;
  for (const auto& e : root.entries)
    if (e.line > first) next = std::min(next, e.line);
  std::istringstream in(text);
  std::string out, l;
  for (std::size_t line = 1; std::getline(in, l); ++line) out += (line >= first && line < next ? std::string() : l) + "\n";
  cs.scenario = parse_scenario(out, file, path.parent_path());
  cs.rig.procedure.start_s = std::max(cs.rig.procedure.start_s, 1.0);
  return cs;
}

RigRun run_rig(const CalibScenario& cs, const std::function<bool(double)>& progress) {
  cs.scenario.validate();
  cs.rig.validate();
  RigRun run;
  run.plan = standard_plan(cs.rig.procedure);
  const BoxParams& box = cs.scenario.model.box;
  const PlatformPlan pp[2] = {platform_plan(run.plan, cs.rig, box, 1),
                              platform_plan(run.plan, cs.rig, box, 2)};
  const Scenario sc = rig_scenario(cs.scenario, run.plan);

  // the twin's simulator on the rate table: MuJoCo steps every physics step (the rig measures
  // where the platforms really rest), the platforms start on the first segment's stops
  twin::SimOptions opt;
  opt.fast_rest = false;
  opt.external_flips = true;
  opt.initial_sign = {pp[0].initial_sign > 0 ? 1 : -1, pp[1].initial_sign > 0 ? 1 : -1};
  twin::Simulator sim(sc, std::make_unique<RigMotion>(run.plan, cs.rig.table_accel_dps2, cs.rig.remount_s),
                      "calibration_rig", opt);
  run.meta = sim.metadata();
  RigCommander commander(pp);
  RigTruthSums sums;
  const double sample_period_s = static_cast<double>(sc.steps_per_sample()) * sc.physics_dt_s;
  const std::uint64_t n_samples = sim.total_samples();
  run.samples.reserve(n_samples);
  Sample s;
  for (std::uint64_t k = 0;; ++k) {
    if (progress && k % 1000 == 0 && !progress(static_cast<double>(k) / static_cast<double>(n_samples)))
      throw std::runtime_error("calibration rig stopped by the user");
    commander.before_sample(sim, static_cast<double>(k) * sample_period_s);
    if (!sim.next(s)) break;
    sums.add(run.plan, s);
    run.samples.push_back(s);
  }
  if (progress) progress(1.0);
  true_matrices(sim, box, sums, run);
  return run;
}

}  // namespace driftless::calib
