// calib.yaml writer and reader.
#include "calibration/calib_file.hpp"

#include <cmath>
#include <fstream>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

#include "calibration/yaml_io.hpp"
#include "estimator/geometry.hpp"
#include "estimator/output_file.hpp"

namespace driftless::calib {
namespace {

constexpr const char* kPosKey[2] = {"minus90", "plus90"};
constexpr const char* kSensorKey[2] = {"sensor1", "sensor2"};

void emit_num_or_null(YAML::Emitter& out, double v) {
  if (std::isfinite(v)) out << yio::num(v);
  else out << YAML::Null;
}


// the hinge axes both writers put after format/method
void emit_hinge_axes(YAML::Emitter& out, const Eigen::Vector3d& hinge1, const Eigen::Vector3d& hinge2) {
  out << YAML::Key << "hinge1_axis" << YAML::Value;
  yio::emit_vec3(out, hinge1);
  out << YAML::Key << "hinge2_axis" << YAML::Value;
  yio::emit_vec3(out, hinge2);
}

// the first keys of the rig block: where the data came from
void emit_rig_origin(YAML::Emitter& out, const std::string& source, double latitude_deg, double sample_rate_hz) {
  out << YAML::Key << "source" << YAML::Value << source;
  out << YAML::Key << "latitude_deg" << YAML::Value;
  emit_num_or_null(out, latitude_deg);
  out << YAML::Key << "sample_rate_hz" << YAML::Value;
  emit_num_or_null(out, sample_rate_hz);
}
}  // namespace

void save_calib(const std::filesystem::path& path, const est::CalibFit& fit,
                const RigConditions& rig, const est::GSensitivityFit* g) {
  using yio::num;
  const est::CalibMatrices mats = fit.matrices();
  YAML::Emitter out;
  out << YAML::Comment(
      "driftless calibrate output (docs/calibration.md). Convention: y_i = M^-1 w_box + b_i,\n"
      "so M (box_from_sensor) replaces R_i in eq. (1)-(2) and M^-1 replaces R_i^T. Units: deg/s, deg.");
  out << YAML::BeginMap;
  out << YAML::Key << "format" << YAML::Value << kCalibFormat;
  out << YAML::Key << "method" << YAML::Value << est::method_name(fit.method);
  emit_hinge_axes(out, rig.hinge1_axis, rig.hinge2_axis);

  out << YAML::Key << "rig" << YAML::Value << YAML::BeginMap;
  emit_rig_origin(out, rig.source, rig.latitude_deg, rig.sample_rate_hz);
  out << YAML::Key << "earth_rate_removed" << YAML::Value << rig.earth_rate_removed;
  out << YAML::Key << "gyro_full_scale_dps" << YAML::Value << num(rig.plan.gyro_full_scale_dps);
  out << YAML::Key << "mean_temp_degc" << YAML::Value << YAML::Flow << YAML::BeginSeq;
  emit_num_or_null(out, rig.mean_temp_c[0]);
  emit_num_or_null(out, rig.mean_temp_c[1]);
  out << YAML::EndSeq;
  out << YAML::Key << "segments" << YAML::Value << YAML::BeginSeq;
  for (std::size_t k = 0; k < rig.plan.segments.size(); ++k) {
    const auto& s = rig.plan.segments[k];
    out << YAML::Flow << YAML::BeginMap;
    out << YAML::Key << "name" << YAML::Value << s.name;
    out << YAML::Key << "axis_box" << YAML::Value;
    yio::emit_vec3(out, s.axis_box);
    emit_segment_span(out, s);
    if (k < rig.samples_used.size())
      out << YAML::Key << "samples_used" << YAML::Value << rig.samples_used[k];
    out << YAML::EndMap;
  }
  out << YAML::EndSeq << YAML::EndMap;

  for (int i = 0; i < 2; ++i) {
    out << YAML::Key << kSensorKey[i] << YAML::Value << YAML::BeginMap;
    for (int p = 0; p < 2; ++p) {
      const est::SensorPositionFit& f = fit.fit[i][p];
      out << YAML::Key << kPosKey[p] << YAML::Value << YAML::BeginMap;
      out << YAML::Key << "M" << YAML::Value;
      yio::emit_mat3(out, f.M);
      out << YAML::Key << "M_sigma" << YAML::Value;
      yio::emit_mat3(out, f.M_sigma);
      out << YAML::Key << "M_inv" << YAML::Value;
      yio::emit_mat3(out, f.M_inv);
      out << YAML::Key << "M_inv_sigma" << YAML::Value;
      yio::emit_mat3(out, f.M_inv_sigma);
      out << YAML::Key << "residual_rms_dps" << YAML::Value;
      yio::emit_vec3(out, f.residual_rms_dps);
      out << YAML::Key << "residual_max_dps" << YAML::Value;
      yio::emit_vec3(out, f.residual_max_dps);
      out << YAML::Key << "samples" << YAML::Value << f.n_samples;
      out << YAML::Key << "bias_dps" << YAML::Value << YAML::BeginSeq;
      for (const auto& b : f.biases) {
        out << YAML::Flow << YAML::BeginMap << YAML::Key << "segment" << YAML::Value << b.segment;
        out << YAML::Key << "value" << YAML::Value;
        yio::emit_vec3(out, b.bias_dps);
        out << YAML::Key << "sigma" << YAML::Value;
        yio::emit_vec3(out, b.sigma_dps);
        out << YAML::EndMap;
      }
      out << YAML::EndSeq << YAML::EndMap;
    }
    // the physical errors M shows (informational; readers ignore them)
    const est::CalibErrors e = est::describe_errors(mats, i, i == 0 ? rig.hinge1_axis : rig.hinge2_axis);
    out << YAML::Key << "errors" << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "scale_error_pct" << YAML::Value;
    yio::emit_vec3(out, 100.0 * e.scale_error);
    out << YAML::Key << "nonorthogonality_deg" << YAML::Value;
    yio::emit_vec3(out, e.nonorthogonality_deg);
    out << YAML::Key << "tilt_minus90_deg" << YAML::Value;
    yio::emit_vec3(out, e.tilt_box_deg[0]);
    out << YAML::Key << "tilt_plus90_deg" << YAML::Value;
    yio::emit_vec3(out, e.tilt_box_deg[1]);
    out << YAML::Key << "travel_error_deg" << YAML::Value << num(e.travel_error_deg);
    out << YAML::Key << "travel_offaxis_deg" << YAML::Value << num(e.travel_offaxis_deg);
    out << YAML::EndMap;
    // y += G f: the gyro's response to specific force, from the per-segment biases
    if (g && g->valid) {
      const auto iu = static_cast<std::size_t>(i);
      out << YAML::Key << "g_sensitivity" << YAML::Value << YAML::BeginMap;
      out << YAML::Key << "G_dps_per_g" << YAML::Value;
      yio::emit_mat3(out, g->G_dps_per_g[iu]);
      out << YAML::Key << "G_sigma" << YAML::Value;
      yio::emit_mat3(out, g->G_sigma[iu]);
      out << YAML::Key << "b0_dps" << YAML::Value;
      yio::emit_vec3(out, g->b0_dps[iu]);
      if (g->temperature_term) {
        out << YAML::Key << "bias_tc_dps_per_degc" << YAML::Value;
        yio::emit_vec3(out, g->bias_tc_dps_per_degc[iu]);
      }
      out << YAML::Key << "residual_rms_dps" << YAML::Value;
      yio::emit_vec3(out, g->residual_rms_dps[iu]);
      out << YAML::Key << "segments" << YAML::Value << g->segments;
      out << YAML::EndMap;
    }
    out << YAML::EndMap;
  }
  out << YAML::EndMap;
  io::write_file(path, std::string(out.c_str()) + "\n");
}

void save_selfcal_calib(const std::filesystem::path& path, const SelfCalibration& sc) {
  using yio::num;
  YAML::Emitter out;
  out << YAML::Comment(
      "driftless estimate --selfcal output (docs/calibration.md). Convention as driftless calibrate's:\n"
      "y_i = M^-1 w_box + b_i + G_i f_i + k_i (T_i - T_ref); M here are the nominal rotations (not\n"
      "calibrated). Units: deg/s, deg, deg/s per g, deg/s per degC, degC.");
  out << YAML::BeginMap;
  out << YAML::Key << "format" << YAML::Value << kCalibFormat;
  out << YAML::Key << "method" << YAML::Value << "selfcal";
  out << YAML::Key << "matrices" << YAML::Value << "nominal";
  emit_hinge_axes(out, sc.hinge1_axis, sc.hinge2_axis);
  out << YAML::Key << "rig" << YAML::Value << YAML::BeginMap;
  emit_rig_origin(out, sc.source, sc.latitude_deg, sc.sample_rate_hz);
  out << YAML::EndMap;
  for (int i = 0; i < 2; ++i) {
    const auto iu = static_cast<std::size_t>(i);
    const Eigen::Vector3d axis = (i == 0 ? sc.hinge1_axis : sc.hinge2_axis).normalized();
    out << YAML::Key << kSensorKey[i] << YAML::Value << YAML::BeginMap;
    for (int p = 0; p < 2; ++p) {
      out << YAML::Key << kPosKey[p] << YAML::Value << YAML::BeginMap << YAML::Key << "M" << YAML::Value;
      yio::emit_mat3(out, geo::rot_about_axis_deg(axis, p == 0 ? -90.0 : 90.0));
      out << YAML::EndMap;
    }
    out << YAML::Key << "g_sensitivity" << YAML::Value << YAML::BeginMap << YAML::Key << "G_dps_per_g" << YAML::Value;
    yio::emit_mat3(out, sc.G_dps_per_g[iu]);
    out << YAML::Key << "G_sigma" << YAML::Value;
    yio::emit_mat3(out, sc.G_sigma[iu]);
    out << YAML::EndMap;
    if (sc.temp_states) {
      out << YAML::Key << "temperature" << YAML::Value << YAML::BeginMap << YAML::Key << "bias_tc_dps_per_degc"
          << YAML::Value;
      yio::emit_vec3(out, sc.temp_coef_dps_per_degc[iu]);
      out << YAML::Key << "bias_tc_sigma_dps_per_degc" << YAML::Value;
      yio::emit_vec3(out, sc.temp_coef_sigma_dps_per_degc[iu]);
      out << YAML::Key << "final_temp_degc" << YAML::Value;
      emit_num_or_null(out, sc.temp_ref_c[iu]);
      out << YAML::EndMap;
    }
    out << YAML::EndMap;
  }
  out << YAML::EndMap;
  io::write_file(path, std::string(out.c_str()) + "\n");
}

est::Calibration CalibFile::to_filter_calibration() const {
  est::Calibration cal = matrices_nominal ? est::Calibration{} : est::to_filter_calibration(M);
  if (has_g_sensitivity) cal.G_dps_per_g = G_dps_per_g;
  cal.has_temp_coef = has_temp_coef;
  cal.temp_coef_dps_per_degc = temp_coef_dps_per_degc;
  cal.temp_coef_sigma_dps_per_degc = temp_coef_sigma_dps_per_degc;
  return cal;
}

CalibFile load_calib(const std::filesystem::path& path) {
  using namespace yio;
  const std::string file = path.string();
  YAML::Node root;
  try {
    root = YAML::LoadFile(file);
  } catch (const YAML::Exception& e) {
    throw InputError(file, static_cast<std::size_t>(e.mark.line) + 1, "",
                     "cannot read calibration file: " + e.msg);
  }
  if (!root.IsMap()) throw InputError(file, 0, "", "not a calibration file (expected a YAML map)");
  const std::string fmt_id = as_string(root["format"], file, "format");
  if (fmt_id != kCalibFormat)
    fail(file, root["format"], "format", std::string("expected '") + kCalibFormat + "', got '" + fmt_id + "'");
  CalibFile c;
  c.method = root["method"] ? as_string(root["method"], file, "method") : "unknown";
  if (root["matrices"]) {
    const std::string m = as_string(root["matrices"], file, "matrices");
    if (m != "nominal" && m != "calibrated") fail(file, root["matrices"], "matrices", "expected nominal or calibrated, got '" + m + "'");
    c.matrices_nominal = m == "nominal";
  }
  if (root["hinge1_axis"]) c.hinge1_axis = as_vec3(root["hinge1_axis"], file, "hinge1_axis");
  if (root["hinge2_axis"]) c.hinge2_axis = as_vec3(root["hinge2_axis"], file, "hinge2_axis");
  if (const YAML::Node rig = root["rig"]) {
    if (rig["latitude_deg"] && !rig["latitude_deg"].IsNull())
      c.latitude_deg = as_double(rig["latitude_deg"], file, "rig.latitude_deg");
    if (rig["earth_rate_removed"]) c.earth_rate_removed = rig["earth_rate_removed"].as<bool>(false);
    if (rig["source"]) c.source = as_string(rig["source"], file, "rig.source");
  }
  for (int i = 0; i < 2; ++i) {
    const YAML::Node s = root[kSensorKey[i]];
    if (!s || !s.IsMap()) fail(file, root, kSensorKey[i], "missing (expected sensor1 and sensor2 maps)");
    for (int p = 0; p < 2; ++p) {
      const std::string key = std::string(kSensorKey[i]) + "." + kPosKey[p];
      const YAML::Node n = s[kPosKey[p]];
      if (!n || !n.IsMap()) fail(file, s, key, "missing (expected minus90 and plus90 maps)");
      c.M.M(i, p) = as_mat3(n["M"], file, key + ".M");
      c.M_sigma[i][p] = n["M_sigma"] ? as_mat3(n["M_sigma"], file, key + ".M_sigma")
                                     : Eigen::Matrix3d::Zero();
      c.residual_rms_dps[i][p] = n["residual_rms_dps"]
                                     ? as_vec3(n["residual_rms_dps"], file, key + ".residual_rms_dps")
                                     : Eigen::Vector3d::Zero();
    }
    if (const YAML::Node gs = s["g_sensitivity"]) {
      const std::string key = std::string(kSensorKey[i]) + ".g_sensitivity.G_dps_per_g";
      c.G_dps_per_g[static_cast<std::size_t>(i)] = as_mat3(gs["G_dps_per_g"], file, key);
      c.has_g_sensitivity = true;
    }
    if (const YAML::Node tn = s["temperature"]) {
      const std::string key = std::string(kSensorKey[i]) + ".temperature.";
      const auto iu = static_cast<std::size_t>(i);
      c.temp_coef_dps_per_degc[iu] = as_vec3(tn["bias_tc_dps_per_degc"], file, key + "bias_tc_dps_per_degc");
      c.temp_coef_sigma_dps_per_degc[iu] =
          as_vec3(tn["bias_tc_sigma_dps_per_degc"], file, key + "bias_tc_sigma_dps_per_degc");
      if ((c.temp_coef_sigma_dps_per_degc[iu].array() < 0.0).any())
        fail(file, tn["bias_tc_sigma_dps_per_degc"], key + "bias_tc_sigma_dps_per_degc", "a sigma must be >= 0 deg/s per degC");
      c.has_temp_coef = true;
    }
  }
  with_location(file, 0, "", [&] { c.M.validate(); });
  return c;
}

}  // namespace driftless::calib
