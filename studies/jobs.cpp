// Sweep runs: scenario overrides, the fast / twin / fdi runners and their metrics.
#include "studies/jobs.hpp"

#include <cmath>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>


#include "estimator/numbers.hpp"
#include "estimator/output_file.hpp"
#include "estimator/pipeline.hpp"
#include "estimator/fdi_input.hpp"
#include "estimator/geometry.hpp"
#include "estimator/random.hpp"
#include "twin/simulator.hpp"
#include "twin/fast_box.hpp"
#include "twin/yaml_doc.hpp"

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

// writes `value` at the dotted path of a YAML document, creating maps on the way
void set_path(fields::Node& root, const std::string& path, fields::Node value) {
  const auto parts = split_path(path);
  if (parts.empty()) throw std::invalid_argument("sweep: empty key path");
  fields::Node* at = &root;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    if (at->is_null()) *at = fields::Node::map();
    if (!at->is_map()) throw std::invalid_argument("sweep: key path '" + path + "': '" + (i == 0 ? std::string("the top") : parts[i - 1]) + "' is not a map");
    fields::Node* next = nullptr;
    for (auto& e : at->entries)
      if (e.key == parts[i]) next = &e.value;
    at = next != nullptr ? next : &at->add(parts[i], fields::Node{});
  }
  *at = std::move(value);
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
  fields::Node root = twin::parse_yaml(base_yaml_, "the sweep's base scenario");
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
      set_path(root, o.path, twin::parse_yaml(o.text, cfg_.file.string() + ": " + o.path));
    }
  }
  set_path(root, "seed", fields::Node::scalar(std::to_string(spec.seed)));
  if (cfg_.duration_s > 0) set_path(root, "duration_s", fields::Node::scalar(exact_number(cfg_.duration_s)));
  const std::string where = cfg_.file.string() + " run " + std::to_string(spec.index);
  s.scenario = parse_scenario(twin::to_yaml(root), where, base_dir_);
  s.estimator.validate();
  if (s.fault_kind < 0 || s.fault_kind > 4) throw std::invalid_argument("sweep: fault.kind must be 0..4");
  if (s.fault_sensor != 1 && s.fault_sensor != 2) throw std::invalid_argument("sweep: fault.sensor must be 1 or 2");
  if (s.fault_axis < 0 || s.fault_axis > 2) throw std::invalid_argument("sweep: fault.axis must be 0..2");
  return s;
}

namespace {

// attitude_<i>.csv: the two attitude error angles (deg) at the comparison points, a nan row at the
// re-alignment (gnuplot breaks its lines there)
class AttitudeCsv final : public est::EstimateSink {
 public:
  AttitudeCsv() { out_ << "t_s,err_driftless_deg,err_zeroed_deg\n"; }
  void on_attitude(const est::AttitudePoint& p) override {
    if (p.realigned) {
      out_ << p.t_s << ",nan,nan\n";
      return;
    }
    out_ << p.t_s << ',' << p.corrected.angle_deg << ',' << p.fixed.angle_deg << '\n';
  }
  std::string text() const { return out_.str(); }

 private:
  std::ostringstream out_;
};

}  // namespace

est::EstimateRunOptions bias_run_options(const RunSetup& setup) {
  est::EstimateRunOptions opt;
  opt.attitude_start_sigma_dps = 0.0;
  opt.attitude_interval_s = 1.0;
  opt.fixed_bias_from = est::FixedBiasFrom::kTruth;
  opt.eval_start_s = setup.eval_start_s >= 0 ? setup.eval_start_s : 0.25 * setup.scenario.duration_s;
  opt.realign_at_eval_start = true;
  return opt;
}

Metrics evaluate_bias(const RunSetup& setup, const log::Metadata& meta, const SampleSource& source,
                      const std::filesystem::path& attitude_csv) {
  AttitudeCsv csv;
  const est::EstimateSummary sum =
      est::run_estimate(meta, Simulator::fields(), source, setup.estimator,
                        attitude_csv.empty() ? nullptr : &csv, bias_run_options(setup));
  if (!attitude_csv.empty()) io::write_file(attitude_csv, csv.text());
  const est::WindowStats& w = sum.window;
  if (!w.available) throw std::runtime_error("sweep: no samples after eval start (duration too short?)");
  Metrics m;
  m.emplace_back("bias_err_rms_dph", w.bias_error_rms_dps * kDphPerDps);
  static const char* names[6] = {"1x", "1y", "1z", "2x", "2y", "2z"};
  for (int i = 0; i < 6; ++i) {
    m.emplace_back(std::string("bias_err_rms_") + names[i] + "_dph", w.component_rms_dps[i] * kDphPerDps);
  }
  m.emplace_back("bias_err_max_dph", w.bias_error_max_dps * kDphPerDps);
  m.emplace_back("bias_err_final_dph", std::sqrt(w.final_error_dps.squaredNorm() / 6.0) * kDphPerDps);
  m.emplace_back("sigma_final_dph", w.sigma_rms_final_dps * kDphPerDps);
  m.emplace_back("nees_mean", w.nees_per_dof_mean);
  m.emplace_back("nis_mean", w.nis_per_dof_mean);
  m.emplace_back("updates", static_cast<double>(sum.counters.updates));
  m.emplace_back("rejected", static_cast<double>(sum.counters.rejected));
  // attitude error accumulated over the evaluation window from a perfect alignment at its start,
  // per hour (NaN without ref_q)
  m.emplace_back("att_drift_dph", sum.drift_net_corrected_deg_per_h);
  m.emplace_back("att_drift_zeroed_dph", sum.drift_net_fixed_deg_per_h);
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
    if (fdi.push(est::fdi_input(s, st, filter)) == est::FdiStatus::kIsolated) break;
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
