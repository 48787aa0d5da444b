// calib.yaml -> twin model prior (see prior.hpp).
#include "calibration/prior.hpp"

#include <Eigen/SVD>

#include "estimator/fields.hpp"
#include "estimator/geometry.hpp"
#include "twin/yaml_doc.hpp"

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

using fields::Table;

// ---- the prior file: emit-only tables, in the keys of the scenario's model block
//      (twin/scenario.cpp, twin/sensor/sensor_params.cpp read it back) ----

// one sensor's effects; which blocks appear depends on what calib.yaml holds
struct PriorEffects {
  bool matrices = false;  // scale factor, misalignment and mounting (calibrated M)
  SensorPrior s;
  bool has_g = false;
  Eigen::Matrix3d G_dps_per_g = Eigen::Matrix3d::Zero();
  bool has_temp = false;
  Eigen::Vector3d tc_dps_per_degc = Eigen::Vector3d::Zero();
  Eigen::Vector3d tc_sigma_dps_per_degc = Eigen::Vector3d::Zero();  // 0: the calibrated value, no draw
  bool enabled = true;
  double sigma = 0.0;  // every run-to-run sigma of the planted effects
};

struct PriorBox {
  Eigen::Vector3d hinge1_axis = Eigen::Vector3d::UnitZ();
  Eigen::Vector3d hinge2_axis = Eigen::Vector3d::UnitX();
  bool has_stops = false;  // a rig's M, or a self-calibration's end_stops (nominal M alone say nothing)
  std::array<Eigen::Vector2d, 2> stop_error_deg{Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero()};
};

struct PriorModel {
  PriorBox box;
  std::array<PriorEffects, 2> effects;
};

// each effect block: {enabled: true, value, sigma: 0} in the sensor catalogue's keys
const Table<PriorEffects>& scale_table() {
  using E = PriorEffects;
  static const Table<E> t = {fields::flag<E>("enabled", &E::enabled),
                             fields::vector<E>("value", "pct", [](auto& e) -> auto& { return e.s.scale_pct; }),
                             fields::number<E>("sigma", "pct", &E::sigma)};
  return t;
}

const Table<PriorEffects>& misalignment_table() {
  using E = PriorEffects;
  static const Table<E> t = {fields::flag<E>("enabled", &E::enabled),
                             fields::matrix3<E>("matrix", "pct", [](auto& e) -> auto& { return e.s.misalignment_pct; }, false),
                             fields::number<E>("sigma", "pct", &E::sigma)};
  return t;
}

const Table<PriorEffects>& mounting_table() {
  using E = PriorEffects;
  static const Table<E> t = {fields::flag<E>("enabled", &E::enabled),
                             fields::vector<E>("angles", "deg", [](auto& e) -> auto& { return e.s.mounting_deg; }),
                             fields::number<E>("sigma", "deg", &E::sigma)};
  return t;
}

const Table<PriorEffects>& g_table() {
  using E = PriorEffects;
  static const Table<E> t = {fields::flag<E>("enabled", &E::enabled),
                             fields::matrix3<E>("matrix", "dps_per_g", &E::G_dps_per_g, false),
                             fields::number<E>("sigma", "dps_per_g", &E::sigma)};
  return t;
}

const Table<PriorEffects>& temp_table() {
  using E = PriorEffects;
  static const Table<E> t = {fields::vector<E>("bias_tc", "dps_per_degc", &E::tc_dps_per_degc),
                             fields::vector<E>("bias_tc_sigma", "dps_per_degc", &E::tc_sigma_dps_per_degc)};
  return t;
}

// a sub-block of `effects`, the same PriorEffects through another table, written when `when` holds
fields::Row<PriorEffects> effect_row(const char* stem, const Table<PriorEffects>& (*table)(), bool PriorEffects::*when) {
  return fields::written_if<PriorEffects>(fields::block<PriorEffects>(stem, [](auto& e) -> auto& { return e; }, table),
                                          [when](const PriorEffects& e) { return e.*when; });
}

const Table<PriorEffects>& effects_table() {
  using E = PriorEffects;
  static const Table<E> t = {
      effect_row("scale_factor", &scale_table, &E::matrices),
      effect_row("misalignment", &misalignment_table, &E::matrices),
      effect_row("mounting_misalignment", &mounting_table, &E::matrices),
      effect_row("g_sensitivity", &g_table, &E::has_g),
      effect_row("temperature", &temp_table, &E::has_temp),
  };
  return t;
}

const Table<PriorEffects>& sensor_table() {
  static const Table<PriorEffects> t = {
      fields::block<PriorEffects>("effects", [](auto& e) -> auto& { return e; }, &effects_table)};
  return t;
}

const Table<PriorBox>& box_table() {
  using B = PriorBox;
  static const Table<B> t = [] {
    Table<B> rows = {fields::vector<B>("hinge1_axis", "", &B::hinge1_axis),
                     fields::vector<B>("hinge2_axis", "", &B::hinge2_axis)};
    for (std::size_t i = 0; i < 2; ++i) {
      rows.push_back(fields::written_if<B>(
          fields::vector<B>(i == 0 ? "stop1_error" : "stop2_error", "deg", [i](auto& b) -> auto& { return b.stop_error_deg[i]; }),
          [](const B& b) { return b.has_stops; }));
    }
    return rows;
  }();
  return t;
}

const Table<PriorModel>& model_table() {
  using M = PriorModel;
  static const Table<M> t = {
      fields::block<M>("box", &M::box, &box_table),
      fields::block<M>("sensor1", [](auto& m) -> auto& { return m.effects[0]; }, &sensor_table),
      fields::block<M>("sensor2", [](auto& m) -> auto& { return m.effects[1]; }, &sensor_table),
  };
  return t;
}

}  // namespace

std::string model_prior_yaml(const CalibFile& c) {
  PriorModel m;
  m.box.hinge1_axis = c.hinge1_axis;
  m.box.hinge2_axis = c.hinge2_axis;
  // a rig's M give the travel between the stops; a self-calibration gives the stops themselves
  m.box.has_stops = !c.matrices_nominal || c.has_end_stops;
  // a self-calibration's E (nominal M) plants its scale factor, misalignment and mounting too
  const est::CalibMatrices M = c.matrices_with_scale();
  for (std::size_t i = 0; i < 2; ++i) {
    PriorEffects& e = m.effects[i];
    e.s = sensor_prior(M, static_cast<int>(i), i == 0 ? c.hinge1_axis : c.hinge2_axis);
    m.box.stop_error_deg[i] = c.has_end_stops ? Eigen::Vector2d(c.end_stop_deg.segment<2>(2 * static_cast<Eigen::Index>(i)))
                                              : e.s.stop_error_deg;
    e.matrices = !c.matrices_nominal || c.has_scale_misalign;
    e.has_g = c.has_g_sensitivity;
    e.G_dps_per_g = c.G_dps_per_g[i];
    e.has_temp = c.has_temp_coef;
    e.tc_dps_per_degc = c.temp_coef_dps_per_degc[i];
  }
  fields::Node root = fields::Node::map();
  root.add("model", fields::write_block(model_table(), m));
  return twin::to_yaml(root, "model prior from a calibration (" + c.source +
                                 "), written by --prior-out; docs/calibration.md") + "\n";
}

}  // namespace driftless::calib
