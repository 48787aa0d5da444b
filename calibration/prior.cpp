// calib.yaml -> twin model prior (see prior.hpp).
#include "calibration/prior.hpp"

#include <Eigen/SVD>
#include <yaml-cpp/yaml.h>

#include "calibration/yaml_io.hpp"
#include "estimator/geometry.hpp"

namespace driftless::calib {

SensorPrior sensor_prior(const est::CalibMatrices& m, int sensor, const Eigen::Vector3d& hinge_axis) {
  const Eigen::Vector3d a = hinge_axis.normalized();
  SensorPrior p;
  const est::CalibErrors e = est::describe_errors(m, sensor, a);
  p.stop_error_deg = Eigen::Vector2d(0.0, e.travel_error_deg);
  // C = M^-1 T at the -90 stop (taken as exact)
  const Eigen::Matrix3d C = m.M(sensor, est::kPosMinus90).inverse() * geo::rot_about_axis_deg(a, -90.0);
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(C, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0) D(2, 2) = -1.0;
  const Eigen::Matrix3d R_sn = svd.matrixU() * D * svd.matrixV().transpose();  // polar rotation
  const Eigen::Matrix3d P = C * R_sn.transpose();                               // (I + K) diag(k)
  const Eigen::Vector3d k = P.diagonal();
  p.scale_pct = 100.0 * (k - Eigen::Vector3d::Ones());
  p.misalignment_pct = 100.0 * (P * k.cwiseInverse().asDiagonal() - Eigen::Matrix3d::Identity());
  p.misalignment_pct.diagonal().setZero();
  // R_nominal_from_sensor = exp([theta]x)
  p.mounting_deg = geo::rotvec_rad(Eigen::Matrix3d(R_sn.transpose())) * kDegPerRad;
  return p;
}

namespace {

// the effects M determines: scale factor, misalignment and mounting (see sensor_prior)
void emit_matrix_effects(YAML::Emitter& out, const SensorPrior& s) {
  using yio::num;
  out << YAML::Key << "scale_factor" << YAML::Value << YAML::BeginMap << YAML::Key << "enabled" << YAML::Value << true
      << YAML::Key << "value_pct" << YAML::Value;
  yio::emit_vec3(out, s.scale_pct);
  out << YAML::Key << "sigma_pct" << YAML::Value << 0 << YAML::EndMap;
  out << YAML::Key << "misalignment" << YAML::Value << YAML::BeginMap << YAML::Key << "enabled" << YAML::Value << true
      << YAML::Key << "matrix_pct" << YAML::Value;
  yio::emit_mat3(out, s.misalignment_pct);
  out << YAML::Key << "sigma_pct" << YAML::Value << 0 << YAML::EndMap;
  out << YAML::Key << "mounting_misalignment" << YAML::Value << YAML::BeginMap << YAML::Key << "enabled" << YAML::Value
      << true << YAML::Key << "angles_deg" << YAML::Value;
  yio::emit_vec3(out, s.mounting_deg);
  out << YAML::Key << "sigma_deg" << YAML::Value << 0 << YAML::EndMap;
}

}  // namespace

std::string model_prior_yaml(const CalibFile& c) {
  using yio::num;
  YAML::Emitter out;
  out << YAML::Comment("model prior from a calibration (" + c.source +
                       "), written by --prior-out; docs/calibration.md");
  out << YAML::BeginMap << YAML::Key << "model" << YAML::Value << YAML::BeginMap;
  const SensorPrior s[2] = {sensor_prior(c.M, 0, c.hinge1_axis), sensor_prior(c.M, 1, c.hinge2_axis)};
  out << YAML::Key << "box" << YAML::Value << YAML::BeginMap;
  out << YAML::Key << "hinge1_axis" << YAML::Value;
  yio::emit_vec3(out, c.hinge1_axis);
  out << YAML::Key << "hinge2_axis" << YAML::Value;
  yio::emit_vec3(out, c.hinge2_axis);
  // nominal matrices (a self-calibration) say nothing about the stops: the scenario's stay
  for (int i = 0; i < 2 && !c.matrices_nominal; ++i) {
    out << YAML::Key << (i == 0 ? "stop1_error_deg" : "stop2_error_deg") << YAML::Value << YAML::Flow
        << YAML::BeginSeq << num(s[i].stop_error_deg[0]) << num(s[i].stop_error_deg[1]) << YAML::EndSeq;
  }
  out << YAML::EndMap;
  for (int i = 0; i < 2; ++i) {
    const auto iu = static_cast<std::size_t>(i);
    out << YAML::Key << (i == 0 ? "sensor1" : "sensor2") << YAML::Value << YAML::BeginMap;
    out << YAML::Key << "effects" << YAML::Value << YAML::BeginMap;
    if (!c.matrices_nominal) emit_matrix_effects(out, s[i]);
    if (c.has_g_sensitivity) {
      out << YAML::Key << "g_sensitivity" << YAML::Value << YAML::BeginMap << YAML::Key << "enabled"
          << YAML::Value << true << YAML::Key << "matrix_dps_per_g" << YAML::Value;
      yio::emit_mat3(out, c.G_dps_per_g[iu]);
      out << YAML::Key << "sigma_dps_per_g" << YAML::Value << 0 << YAML::EndMap;
    }
    if (c.has_temp_coef) {
      out << YAML::Key << "temperature" << YAML::Value << YAML::BeginMap << YAML::Key << "bias_tc_dps_per_degc"
          << YAML::Value;
      yio::emit_vec3(out, c.temp_coef_dps_per_degc[iu]);
      out << YAML::Key << "bias_tc_sigma_dps_per_degc" << YAML::Value;
      yio::emit_vec3(out, Eigen::Vector3d::Zero());
      out << YAML::EndMap;
    }
    out << YAML::EndMap << YAML::EndMap;
  }
  out << YAML::EndMap << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

}  // namespace driftless::calib
