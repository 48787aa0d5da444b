// Sweep runs: scenario overrides, the fast / twin / fdi runners and their metrics.
#include "studies/jobs.hpp"

#include <cmath>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

#include "estimator/numbers.hpp"
#include "estimator/output_file.hpp"
#include "estimator/attitude.hpp"
#include "estimator/geometry.hpp"
#include "estimator/random.hpp"
#include "twin/simulator.hpp"
#include "twin/fast_box.hpp"

namespace driftless::studies {

using twin::Scenario;
using twin::Simulator;
using twin::parse_scenario;
using twin::emit_scenario;
using twin::load_scenario;
using twin::default_scenario;
namespace {

constexpr double kDphPerDps = 3600.0;

std::vector<std::string> split_path(const std::string& path) {
  std::vector<std::string> parts;
  std::stringstream ss(path);
  std::string p;
  while (std::getline(ss, p, '.')) parts.push_back(p);
  return parts;
}

// writes `value` (YAML text) at the dotted path, creating maps on the way
void set_path(YAML::Node root, const std::string& path, const YAML::Node& value) {
  const auto parts = split_path(path);
  if (parts.empty()) throw std::invalid_argument("sweep: empty key path");
  std::vector<YAML::Node> chain{root};
  for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
    YAML::Node next = chain.back()[parts[i]];
    if (!next.IsDefined() || next.IsNull()) {
      chain.back()[parts[i]] = YAML::Node(YAML::NodeType::Map);
      next = chain.back()[parts[i]];
    }
    if (!next.IsMap()) throw std::invalid_argument("sweep: key path '" + path + "': '" + parts[i] + "' is not a map");
    chain.push_back(next);
  }
  chain.back()[parts.back()] = value;
}

std::string number_text(double v) { return exact_number(v); }

struct Override {
  std::string path;
  std::string text;   // YAML value text
  double number = 0;  // the value when numeric
  bool numeric = false;
};

}  // namespace

SetupBuilder::SetupBuilder(const SweepConfig& cfg) : cfg_(cfg) {
  const std::string sc = cfg.scenario.string();
  const Scenario base = sc.empty() ? default_scenario() : load_scenario(sc);
  base_yaml_ = emit_scenario(base);
  base_dir_ = base.base_dir;
}

RunSetup SetupBuilder::build(const RunSpec& spec) const {
  std::vector<Override> ov;
  for (const auto& [k, v] : cfg_.fixed) {
    Override o{k, v, 0, false};
    char* end = nullptr;
    o.number = std::strtod(v.c_str(), &end);
    o.numeric = end && *end == '\0' && !v.empty();
    ov.push_back(o);
  }
  for (std::size_t a = 0; a < cfg_.grid.size(); ++a) {
    const auto& ax = cfg_.grid[a];
    const double v = spec.values.at(a);
    for (const auto& path : ax.set) {
      const std::string t = number_text(v);
      const bool vec = ax.vector3 && path.rfind("estimator.", 0) != 0;  // filter keys are scalars
      if (ax.boolean) {
        ov.push_back({path, v != 0 ? "true" : "false", v, false});
      } else {
        ov.push_back({path, vec ? "[" + t + ", " + t + ", " + t + "]" : t, v, !vec});
      }
    }
  }
  RunSetup s;
  YAML::Node root = YAML::Load(base_yaml_);
  for (const auto& o : ov) {
    if (o.path.rfind("estimator.", 0) == 0) {
      set_config_value(s.estimator, o.path.substr(10), o.text);
    } else if (o.path.rfind("fault.", 0) == 0 || o.path == "eval_start_s") {
      if (!o.numeric) throw std::invalid_argument("sweep: '" + o.path + "' needs a number");
      const std::string k = o.path;
      if (k == "fault.kind") s.fault_kind = static_cast<int>(o.number);
      else if (k == "fault.sensor") s.fault_sensor = static_cast<int>(o.number);
      else if (k == "fault.axis") s.fault_axis = static_cast<int>(o.number);
      else if (k == "fault.t_s") s.fault_t_s = o.number;
      else if (k == "fault.size") s.fault_size = o.number;
      else if (k == "eval_start_s") s.eval_start_s = o.number;
      else throw std::invalid_argument("sweep: unknown key '" + k + "' (fault.kind, fault.sensor, fault.axis, fault.t_s, fault.size)");
    } else {
      set_path(root, o.path, YAML::Load(o.text));
    }
  }
  root["seed"] = spec.seed;
  if (cfg_.duration_s > 0) root["duration_s"] = cfg_.duration_s;
  const std::string where = cfg_.file.string() + " run " + std::to_string(spec.index);
  s.scenario = parse_scenario(YAML::Dump(root), where, base_dir_);
  s.estimator.validate();
  if (s.fault_kind < 0 || s.fault_kind > 4) throw std::invalid_argument("sweep: fault.kind must be 0..4");
  if (s.fault_sensor != 1 && s.fault_sensor != 2) throw std::invalid_argument("sweep: fault.sensor must be 1 or 2");
  if (s.fault_axis < 0 || s.fault_axis > 2) throw std::invalid_argument("sweep: fault.axis must be 0..2");
  return s;
}

Metrics evaluate_bias(const RunSetup& setup, const log::Metadata& meta, const SampleSource& source,
                      const std::filesystem::path& attitude_csv) {
  // attitude.csv: collected here, written through the output helper when the run is done
  const bool att_file = !attitude_csv.empty();
  std::ostringstream att_out;
  if (att_file) att_out << "t_s,err_driftless_deg,err_zeroed_deg\n";
  double next_att_out_s = 0.0;
  est::DriftlessFilter filter(setup.estimator, est::box_geometry_from_metadata(meta));
  const double eval_start =
      setup.eval_start_s >= 0 ? setup.eval_start_s : 0.25 * setup.scenario.duration_s;
  Sample s;
  double sum2 = 0, nees = 0, nis = 0, maxe = 0;
  est::Vector6d comp2 = est::Vector6d::Zero();
  est::Vector6d last_err = est::Vector6d::Zero();
  long n = 0, n_nis = 0;
  std::uint64_t last_update = 0;
  // attitude (paper Fig. 9): strapdown from the DriftLess-corrected rate, and from the gyros with
  // their bias zeroed once at the first sample (a perfect turn-on calibration, then drift: the
  // paper's "without DriftLess"); both start on the reference attitude
  est::AttitudeIntegrator att_dl(setup.scenario.latitude_deg), att_zero(setup.scenario.latitude_deg);
  Eigen::Quaterniond err_dl0 = Eigen::Quaterniond::Identity(), err_zero0 = Eigen::Quaterniond::Identity();
  bool att_window = false;
  double att_t0 = kNaN, att_t1 = kNaN;
  Eigen::Quaterniond err_dl1 = Eigen::Quaterniond::Identity(), err_zero1 = Eigen::Quaterniond::Identity();
  while (source(s)) {
    filter.push(s);
    if (s.ref_q_wxyz.allFinite() && s.true_bias1_dps.allFinite() && s.true_bias2_dps.allFinite()) {
      const est::SampleOutput& out = filter.output();
      if (!att_dl.initialized()) {
        // the true bias at the first sample, held: the filter fuses its rate with it
        // (rate_body_fixed_dps), the same fusion as the corrected rate
        est::Vector6d bias_at_start;
        bias_at_start << s.true_bias1_dps, s.true_bias2_dps;
        filter.set_fixed_bias_dps(bias_at_start);
        att_dl.reset(s.q_enu_from_body(), s.t_s);
        att_zero.reset(s.q_enu_from_body(), s.t_s);
      } else {
        att_dl.step(s.t_s, out.rate_body_dps);
        att_zero.step(s.t_s, out.rate_body_fixed_dps);
      }
      const Eigen::Quaterniond q_ref = s.q_enu_from_body();
      const Eigen::Quaterniond e_dl = att_dl.q_enu_from_body() * q_ref.conjugate();
      const Eigen::Quaterniond e_zero = att_zero.q_enu_from_body() * q_ref.conjugate();
      if (!att_window && s.t_s >= eval_start) {
        // re-align both on the reference at the window start: the drift is what accumulates
        // after it (an offset left by the filter's convergence is fixed in the body frame and
        // would turn with the box in an ENU error, reading as drift)
        att_window = true;
        att_t0 = s.t_s;
        att_dl.reset(q_ref, s.t_s);
        att_zero.reset(q_ref, s.t_s);
        err_dl0 = err_zero0 = Eigen::Quaterniond::Identity();
        next_att_out_s = s.t_s;
        if (att_file) att_out << s.t_s << ",nan,nan\n";  // gnuplot: break the lines
      } else if (att_file && s.t_s >= next_att_out_s) {
        att_out << s.t_s << ',' << geo::rotvec_rad(e_dl).norm() * kDegPerRad << ','
                << geo::rotvec_rad(e_zero).norm() * kDegPerRad << '\n';
        next_att_out_s += 1.0;
      }
      att_t1 = s.t_s;
      err_dl1 = e_dl;
      err_zero1 = e_zero;
    }
    if (filter.counters().updates > last_update) {
      last_update = filter.counters().updates;
      const auto& u = filter.last_update();
      if (u.accepted && std::isfinite(u.nis) && u.t_s >= eval_start) {
        nis += u.nis / u.dim;
        ++n_nis;
      }
    }
    if (s.t_s < eval_start || !s.true_bias1_dps.allFinite()) continue;
    est::Vector6d truth;
    truth << s.true_bias1_dps, s.true_bias2_dps;
    const est::Vector6d e = filter.bias_dps() - truth;
    sum2 += e.squaredNorm();
    comp2 += e.cwiseAbs2();
    maxe = std::max(maxe, e.cwiseAbs().maxCoeff());
    nees += e.dot(filter.covariance_dps2().ldlt().solve(e)) / 6.0;
    last_err = e;
    ++n;
  }
  if (att_file) io::write_file(attitude_csv, att_out.str());
  if (n == 0) throw std::runtime_error("sweep: no samples after eval start (duration too short?)");
  Metrics m;
  m.emplace_back("bias_err_rms_dph", std::sqrt(sum2 / (6.0 * n)) * kDphPerDps);
  static const char* names[6] = {"1x", "1y", "1z", "2x", "2y", "2z"};
  for (int i = 0; i < 6; ++i) {
    m.emplace_back(std::string("bias_err_rms_") + names[i] + "_dph", std::sqrt(comp2[i] / n) * kDphPerDps);
  }
  m.emplace_back("bias_err_max_dph", maxe * kDphPerDps);
  m.emplace_back("bias_err_final_dph", std::sqrt(last_err.squaredNorm() / 6.0) * kDphPerDps);
  m.emplace_back("sigma_final_dph", std::sqrt(filter.covariance_dps2().trace() / 6.0) * kDphPerDps);
  m.emplace_back("nees_mean", nees / n);
  m.emplace_back("nis_mean", n_nis ? nis / n_nis : std::nan(""));
  m.emplace_back("updates", static_cast<double>(filter.counters().updates));
  m.emplace_back("rejected", static_cast<double>(filter.counters().rejected));
  // attitude error accumulated over the evaluation window from a perfect alignment at its start,
  // per hour (NaN without ref_q)
  const double window_h = (att_t1 - att_t0) / 3600.0;
  const auto drift = [&](const Eigen::Quaterniond& e0, const Eigen::Quaterniond& e1) {
    if (!att_window || !(window_h > 0)) return kNaN;
    return geo::rotvec_rad(e1 * e0.conjugate()).norm() * kDegPerRad / window_h;
  };
  m.emplace_back("att_drift_dph", drift(err_dl0, err_dl1));
  m.emplace_back("att_drift_zeroed_dph", drift(err_zero0, err_zero1));
  return m;
}

Metrics evaluate_fdi(const RunSetup& setup, const log::Metadata& meta, const SampleSource& source) {
  est::DriftlessFilter filter(setup.estimator, est::box_geometry_from_metadata(meta));
  est::FdiParams fp;
  fp.sample_rate_hz = setup.scenario.sample_rate_hz;
  est::FaultDetector fdi(fp);
  rnd::NormalStream gauss(setup.scenario.seed, rnd::Stream::kFaultInjection);
  const double sigma_dps =
      setup.estimator.noise_density_dps_rthz * std::sqrt(setup.scenario.sample_rate_hz);
  const est::FaultKind planted = static_cast<est::FaultKind>(setup.fault_kind);
  // fault.size 0: the default size of the kind (bias step 0.5 deg/s, noise x5, scale +5 %)
  double size = setup.fault_size;
  if (size == 0.0) {
    size = planted == est::FaultKind::kBiasStep ? 0.5
           : planted == est::FaultKind::kNoiseBurst ? 5.0
           : planted == est::FaultKind::kScaleChange ? 0.05 : 0.0;
  }
  double stuck_value = kNaN;
  Sample s;
  while (source(s)) {
    const bool active = planted != est::FaultKind::kNone && s.t_s >= setup.fault_t_s;
    Eigen::Vector3d& y = setup.fault_sensor == 1 ? s.gyro1_dps : s.gyro2_dps;
    const int k = setup.fault_axis;
    if (active) {
      switch (planted) {
        case est::FaultKind::kStuck:
          if (std::isnan(stuck_value)) stuck_value = y[k];
          y[k] = stuck_value;
          break;
        case est::FaultKind::kBiasStep: y[k] += size; break;
        case est::FaultKind::kNoiseBurst:
          y[k] += std::sqrt(std::max(0.0, size * size - 1.0)) * sigma_dps * gauss();
          break;
        case est::FaultKind::kScaleChange: {
          const double plat = setup.fault_sensor == 1 ? s.true_plat1_deg : s.true_plat2_deg;
          const Eigen::Vector3d a = setup.scenario.model.box.hinge_axis(setup.fault_sensor);
          const Eigen::Matrix3d R = geo::rot_about_axis_deg(a, plat);
          y[k] += size * (R.transpose() * s.true_rate_body_dps)[k];
          break;
        }
        case est::FaultKind::kNone: break;
      }
    }
    const est::PushStatus st = filter.push(s);
    est::FdiInput in;
    in.t_s = s.t_s;
    in.gyro1_dps = s.gyro1_dps;
    in.gyro2_dps = s.gyro2_dps;
    in.at_rest = (st == est::PushStatus::kAccumulating || st == est::PushStatus::kUpdated ||
                  st == est::PushStatus::kRejected) &&
                 std::isfinite(s.plat1_deg) && std::isfinite(s.plat2_deg);
    if (in.at_rest) {
      in.R_body_from_sensor1 = filter.body_from_sensor(1, s.plat1_deg);
      in.R_body_from_sensor2 = filter.body_from_sensor(2, s.plat2_deg);
    }
    in.bias_dps = filter.bias_dps();
    in.bias_cov_dps2 = filter.covariance_dps2();
    if (fdi.push(in) == est::FdiStatus::kIsolated) break;
  }
  const auto& f = fdi.fault();
  const auto alarm = fdi.first_alarm_s();
  const bool has_fault = planted != est::FaultKind::kNone;
  Metrics m;
  const bool false_alarm = alarm && (!has_fault || *alarm < setup.fault_t_s);
  m.emplace_back("false_alarm", false_alarm ? 1.0 : 0.0);
  m.emplace_back("detected", has_fault && alarm && !false_alarm ? 1.0 : 0.0);
  m.emplace_back("alarm_delay_s", has_fault && alarm && !false_alarm ? *alarm - setup.fault_t_s : kNaN);
  m.emplace_back("isolation_delay_s",
                 has_fault && f && !false_alarm ? f->t_isolated_s - setup.fault_t_s : kNaN);
  m.emplace_back("kind_correct", has_fault && f && f->kind == planted ? 1.0 : 0.0);
  m.emplace_back("sensor_correct", has_fault && f && f->sensor == setup.fault_sensor ? 1.0 : 0.0);
  m.emplace_back("axis_correct", has_fault && f && f->sensor == setup.fault_sensor && f->axis == setup.fault_axis ? 1.0 : 0.0);
  return m;
}

SweepJob make_job(const SweepConfig& cfg, const std::filesystem::path& log_dir, const std::atomic<bool>* stop) {
  auto builder = std::make_shared<SetupBuilder>(cfg);
  if (!log_dir.empty()) std::filesystem::create_directories(log_dir);
  const std::string runner = cfg.runner;
  return [builder, runner, log_dir, stop](const RunSpec& spec) {
    const RunSetup setup = builder->build(spec);
    std::unique_ptr<Simulator> sim;
    std::unique_ptr<twin::FastBox> box;
    log::Metadata meta;
    SampleSource next;
    if (runner == "twin" || runner == "fdi_twin") {
      sim = std::make_unique<Simulator>(setup.scenario);
      meta = sim->metadata();
      next = [&](Sample& s) { return sim->next(s); };
    } else {
      box = std::make_unique<twin::FastBox>(setup.scenario);
      meta = box->metadata();
      next = [&](Sample& s) { return box->next(s); };
    }
    // a stop request ends the run in progress at its next sample (a 14 h run would otherwise finish first)
    if (stop != nullptr) {
      next = [inner = std::move(next), stop](Sample& s) {
        if (stop->load(std::memory_order_relaxed)) throw std::runtime_error("stopped");
        return inner(s);
      };
    }
    std::unique_ptr<log::LogWriter> writer;
    SampleSource source = next;
    if (!log_dir.empty()) {
      writer = std::make_unique<log::LogWriter>(log_dir / ("run_" + std::to_string(spec.index) + ".csv"),
                                                meta, Simulator::fields());
      source = [&](Sample& s) {
        if (!next(s)) return false;
        writer->write(s);
        return true;
      };
    }
    const bool fdi = runner == "fdi" || runner == "fdi_twin";
    const std::filesystem::path att_csv =
        log_dir.empty() ? std::filesystem::path{} : log_dir / ("attitude_" + std::to_string(spec.index) + ".csv");
    Metrics m = fdi ? evaluate_fdi(setup, meta, source) : evaluate_bias(setup, meta, source, att_csv);
    if (writer) {
      Sample rest;
      while (source(rest)) {}  // the fdi runner stops at isolation: finish the log
      writer->finish(true);
    }
    return m;
  };
}

}  // namespace driftless::studies
