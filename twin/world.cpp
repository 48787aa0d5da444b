#include "twin/world.hpp"

#include <cmath>
#include <algorithm>
#include <cstring>
#include <sstream>
#include <stdexcept>

#include <fmt/core.h>

#include "estimator/numbers.hpp"
#include "estimator/sample.hpp"
#include "twin/embedded.hpp"
#include "twin/motion.hpp"

namespace driftless::twin {
namespace {

void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument(what);
}

std::string num(double v) { return exact_number(v); }  // MuJoCo reads back the same double
std::string vec3(const Eigen::Vector3d& v) { return num(v.x()) + " " + num(v.y()) + " " + num(v.z()); }

// sets attribute `attr` of the element named `name` (the one tag holding name="...") in `xml`
void set_attr(std::string& xml, const std::string& name, const std::string& attr,
              const std::string& value) {
  const std::string key = "name=\"" + name + "\"";
  const auto at = xml.find(key);
  if (at == std::string::npos || xml.find(key, at + 1) != std::string::npos) {
    throw std::logic_error("box model: element '" + name + "' missing or not unique in the MJCF");
  }
  const auto open = xml.rfind('<', at);
  const auto close = xml.find('>', at);
  std::string tag = xml.substr(open, close - open);
  const std::string a = " " + attr + "=\"";
  const auto pa = tag.find(a);
  if (pa != std::string::npos) {
    const auto v0 = pa + a.size();
    const auto v1 = tag.find('"', v0);
    tag.replace(v0, v1 - v0, value);
  } else {
    const bool self_closing = !tag.empty() && tag.back() == '/';
    tag.insert(self_closing ? tag.size() - 1 : tag.size(), a + value + "\" ");
  }
  xml.replace(open, close - open, tag);
}

// end of the element opened at `open` ('<tag ...'): past "/>" for a self-closing tag, else past
// the matching "</tag>" (nested tags of the same name counted)
std::size_t element_end(const std::string& xml, std::size_t open, const std::string& tag) {
  const std::size_t gt = xml.find('>', open);
  if (gt == std::string::npos) throw std::logic_error("box model: unterminated <" + tag + ">");
  if (xml[gt - 1] == '/') return gt + 1;
  int depth = 1;
  std::size_t at = gt + 1;
  while (depth > 0) {
    const std::size_t next_open = xml.find("<" + tag, at), next_close = xml.find("</" + tag + ">", at);
    if (next_close == std::string::npos) throw std::logic_error("box model: unclosed <" + tag + ">");
    if (next_open != std::string::npos && next_open < next_close) {
      ++depth;
      at = next_open + 1;
    } else {
      --depth;
      at = next_close + tag.size() + 3;
    }
  }
  return at;
}

// removes every <tag ...> element whose opening tag contains `marker` (empty: every one)
void erase_elements(std::string& xml, const std::string& tag, const std::string& marker) {
  std::size_t at = 0;
  while ((at = xml.find("<" + tag, at)) != std::string::npos) {
    const char after = xml[at + tag.size() + 1];
    const std::size_t gt = xml.find('>', at);
    const bool same_tag = after == ' ' || after == '>' || after == '/' || after == '\n';
    if (same_tag && (marker.empty() || xml.substr(at, gt - at).find(marker) != std::string::npos)) {
      xml.erase(at, element_end(xml, at, tag) - at);
    } else {
      ++at;
    }
  }
}

void quat_to_mj(const Eigen::Quaterniond& q, mjtNum* out) {
  out[0] = q.w();
  out[1] = q.x();
  out[2] = q.y();
  out[3] = q.z();
}

}  // namespace

void MotorParams::validate() const {
  require(max_speed_dps > 0 && std::isfinite(max_speed_dps), "model.box.motor.max_speed_dps must be > 0 deg/s");
  require(max_accel_dps2 > 0 && std::isfinite(max_accel_dps2), "model.box.motor.max_accel_dps2 must be > 0 deg/s^2");
  require(kp_nm_per_rad > 0, "model.box.motor.kp_nm_per_rad must be > 0 N m/rad");
  require(kv_nms_per_rad >= 0, "model.box.motor.kv_nms_per_rad must be >= 0 N m s/rad");
  require(stall_torque_nm > 0, "model.box.motor.stall_torque_nm must be > 0 N m");
  require(rotor_inertia_kgm2 > 0, "model.box.motor.rotor_inertia_kgm2 must be > 0 kg m^2");
  require(damping_nms_per_rad >= 0, "model.box.motor.damping_nms_per_rad must be >= 0 N m s/rad");
  require(overtravel_deg >= 0 && overtravel_deg <= 30, "model.box.motor.overtravel_deg must be in [0, 30] deg");
}

void BoxParams::validate() const {
  require(hinge1_axis.allFinite() && hinge1_axis.norm() > 1e-9, "model.box.hinge1_axis must be a non-zero 3-vector");
  require(hinge2_axis.allFinite() && hinge2_axis.norm() > 1e-9, "model.box.hinge2_axis must be a non-zero 3-vector");
  require(hinge1_axis.normalized().cross(hinge2_axis.normalized()).norm() > 0.1,
          "model.box.hinge1_axis and hinge2_axis must not be (nearly) parallel: the biases would "
          "not be observable");
  require(end_stop_deg > 0 && end_stop_deg <= 170, "model.box.end_stop_deg must be in (0, 170] deg");
  for (double e : {stop1_error_deg[0], stop1_error_deg[1], stop2_error_deg[0], stop2_error_deg[1]}) {
    require(std::isfinite(e) && std::abs(e) <= 10,
            "model.box.stop1_error_deg / stop2_error_deg must be within +/-10 deg");
  }
  require(stop_timeconst_s >= 0.002 && stop_timeconst_s <= 1,
          "model.box.stop_timeconst_s must be in [0.002, 1] s (>= 2 physics steps)");
  // below ~0.5 the light platform chatters on the stop at a 1 ms step (a discrete limit cycle)
  require(stop_dampratio >= 0.5 && stop_dampratio <= 10, "model.box.stop_dampratio must be in [0.5, 10]");
  motor.validate();
}

Eigen::Vector3d BoxParams::hinge_axis(int i) const {
  return (i == 1 ? hinge1_axis : hinge2_axis).normalized();
}

double BoxParams::stop_rad(int i, int sign) const {
  const Eigen::Vector2d& e = i == 1 ? stop1_error_deg : stop2_error_deg;
  return sign > 0 ? (end_stop_deg + e[1]) * kRadPerDeg : (-end_stop_deg + e[0]) * kRadPerDeg;
}

const char* carrier_name(Carrier c) {
  switch (c) {
    case Carrier::none: return "none";
    case Carrier::pan_tilt: return "pan_tilt";
    case Carrier::vehicle: return "vehicle";
    case Carrier::ship: return "ship";
  }
  return "none";
}

const std::string& embedded_box_mjcf() {
  static const std::string xml(embedded::kBoxMjcf);
  return xml;
}

std::string box_mjcf(const BoxParams& box) {
  box.validate();
  std::string xml = embedded_box_mjcf();
  const auto& m = box.motor;
  for (int i : {1, 2}) {
    const std::string n = std::to_string(i);
    const Eigen::Vector3d a = box.hinge_axis(i);
    set_attr(xml, "hinge" + n, "axis", vec3(a));
    set_attr(xml, "hinge" + n, "range",
             num(box.stop_rad(i, -1) * kDegPerRad) + " " + num(box.stop_rad(i, +1) * kDegPerRad));
    set_attr(xml, "hinge" + n, "solreflimit", num(box.stop_timeconst_s) + " " + num(box.stop_dampratio));
    set_attr(xml, "hinge" + n, "armature", num(m.rotor_inertia_kgm2));
    set_attr(xml, "hinge" + n, "damping", num(m.damping_nms_per_rad));
    // the PCB lies across its hinge axis, so it turns in its own plane
    set_attr(xml, "pcb" + n, "zaxis", vec3(a));
    set_attr(xml, "motor" + n, "gainprm", num(m.kp_nm_per_rad));
    set_attr(xml, "motor" + n, "biasprm", "0 " + num(-m.kp_nm_per_rad) + " " + num(-m.kv_nms_per_rad));
    set_attr(xml, "motor" + n, "forcerange", num(-m.stall_torque_nm) + " " + num(m.stall_torque_nm));
  }
  return xml;
}

std::string physics_only_mjcf(const std::string& xml) {
  std::string out = xml;
  erase_elements(out, "body", "mocap=\"true\"");
  erase_elements(out, "geom", "class=\"visual\"");
  erase_elements(out, "camera", "");
  erase_elements(out, "light", "");
  return out;
}

ModelPtr load_mjcf_string(const std::string& xml, const std::string& name) {
  auto vfs = std::make_unique<mjVFS>();
  mj_defaultVFS(vfs.get());
  if (mj_makeEmptyFileVFS(vfs.get(), name.c_str(), static_cast<int>(xml.size())) != 0) {
    throw std::runtime_error("MuJoCo: cannot create in-memory file " + name);
  }
  const int idx = mj_findFileVFS(vfs.get(), name.c_str());
  std::memcpy(vfs->filedata[idx], xml.data(), xml.size());
  char err[1024] = "";
  mjModel* m = mj_loadXML(name.c_str(), vfs.get(), err, sizeof err);
  mj_deleteVFS(vfs.get());
  if (m == nullptr) throw std::runtime_error("MuJoCo could not load " + name + ": " + err);
  return ModelPtr(m, mj_deleteModel);
}

World::World(const BoxParams& box, double timestep_s, ModelScope scope)
    : box_(box), scope_(scope), model_(nullptr, mj_deleteModel), data_(nullptr, mj_deleteData) {
  require(timestep_s > 0 && timestep_s <= 0.005, "physics_dt_s must be in (0, 0.005] s");
  const std::string xml = box_mjcf(box_);
  model_ = load_mjcf_string(scope == ModelScope::full ? xml : physics_only_mjcf(xml), "driftless_box.xml");
  model_->opt.timestep = timestep_s;
  data_ = DataPtr(mj_makeData(model_.get()), mj_deleteData);
  if (!data_) throw std::runtime_error("MuJoCo: mj_makeData failed");

  const mjModel* m = model_.get();
  const int drive_x = id(mjOBJ_JOINT, "drive_x");
  qadr_drive_ = m->jnt_qposadr[drive_x];
  vadr_drive_ = m->jnt_dofadr[drive_x];
  for (int i = 0; i < 2; ++i) {
    const std::string n = std::to_string(i + 1);
    const int j = id(mjOBJ_JOINT, ("hinge" + n).c_str());
    qadr_hinge_[i] = m->jnt_qposadr[j];
    vadr_hinge_[i] = m->jnt_dofadr[j];
    act_motor_[i] = id(mjOBJ_ACTUATOR, ("motor" + n).c_str());
    site_imu_[i] = id(mjOBJ_SITE, ("imu" + n).c_str());
    sadr_gyro_[i] = m->sensor_adr[id(mjOBJ_SENSOR, ("gyro" + n).c_str())];
    sadr_accel_[i] = m->sensor_adr[id(mjOBJ_SENSOR, ("accel" + n).c_str())];
    cache_platform(i, j, site_imu_[i]);
  }
  gravity_enu_mps2_ = Eigen::Vector3d(m->opt.gravity[0], m->opt.gravity[1], m->opt.gravity[2]);
  body_box_ = id(mjOBJ_BODY, "box");
  if (scope == ModelScope::full) {
    body_pan_ = id(mjOBJ_BODY, "pantilt_pan");
    body_tilt_ = id(mjOBJ_BODY, "pantilt_tilt");
    body_vehicle_ = id(mjOBJ_BODY, "vehicle");
    body_ship_ = id(mjOBJ_BODY, "ship");
    mocap_pan_ = m->body_mocapid[body_pan_];
    mocap_tilt_ = m->body_mocapid[body_tilt_];
    mocap_vehicle_ = m->body_mocapid[body_vehicle_];
    mocap_ship_ = m->body_mocapid[body_ship_];
  }
  scratch_qacc_.resize(static_cast<std::size_t>(m->nv));
  scratch_res_.resize(static_cast<std::size_t>(m->nv));
  geom_alpha_.resize(static_cast<std::size_t>(m->ngeom));
  for (int g = 0; g < m->ngeom; ++g) geom_alpha_[static_cast<std::size_t>(g)] = m->geom_rgba[4 * g + 3];

  // start at rest, both platforms on their + stops
  mj_resetData(m, data_.get());
  set_base(Eigen::Vector3d::Zero(), Eigen::Quaterniond::Identity(), Eigen::Vector3d::Zero(),
           Eigen::Vector3d::Zero());
  mj_forward(m, data_.get());
}

namespace {
Eigen::Vector3d vec(const mjtNum* v) { return {v[0], v[1], v[2]}; }
Eigen::Matrix3d mat(const mjtNum* q) { return Eigen::Quaterniond(q[0], q[1], q[2], q[3]).toRotationMatrix(); }
}  // namespace

void World::cache_platform(int i, int joint, int site) {
  const mjModel* m = model_.get();
  const int body = m->jnt_bodyid[joint];
  const int box = id(mjOBJ_BODY, "box");
  // the closed forms below take the box frame as the drive's frame and the platforms as its children
  if (m->body_parentid[body] != box || vec(m->body_pos + 3 * box).norm() != 0.0 ||
      m->body_quat[4 * box] != 1.0) {
    throw std::logic_error("box model: the box body must sit at the drive's origin and carry the platforms");
  }
  if (m->site_bodyid[site] != body) throw std::logic_error("box model: sensor site off its platform");
  Platform& p = plat_[i];
  const Eigen::Vector3d jnt_pos = vec(m->jnt_pos + 3 * joint);
  p.R_box_from_plat0 = mat(m->body_quat + 4 * body);
  p.anchor_box_m = vec(m->body_pos + 3 * body) + p.R_box_from_plat0 * jnt_pos;
  p.axis_plat = vec(m->jnt_axis + 3 * joint).normalized();
  p.site_from_anchor_m = vec(m->site_pos + 3 * site) - jnt_pos;
  p.R_plat_from_site = mat(m->site_quat + 4 * site);
  p.mass_kg = m->body_mass[body];
  p.com_from_anchor_m = vec(m->body_ipos + 3 * body) - jnt_pos;
  const Eigen::Matrix3d R_iq = mat(m->body_iquat + 4 * body);
  p.inertia_com_kgm2 = R_iq * vec(m->body_inertia + 3 * body).asDiagonal() * R_iq.transpose();
}

Eigen::Matrix3d World::R_box_from_plat(int i, double angle_rad) const {
  const Platform& p = plat_[i - 1];
  return p.R_box_from_plat0 * Eigen::AngleAxisd(angle_rad, p.axis_plat).toRotationMatrix();
}

SiteMotion World::site_motion(int i, const MotionState& base, double angle_rad, double rate_radps,
                              double accel_radps2) const {
  const Platform& p = plat_[i - 1];
  const Eigen::Matrix3d R_bp = R_box_from_plat(i, angle_rad);
  const Eigen::Matrix3d R_box_from_site = R_bp * p.R_plat_from_site;
  const Eigen::Vector3d& w = base.w_body_radps;
  const Eigen::Vector3d& dw = base.dw_body_radps2;
  const Eigen::Vector3d axis = p.R_box_from_plat0 * p.axis_plat;  // box axes (turns with no angle)
  // site position: box origin -> anchor -> site; its motion relative to the box is the hinge's
  const Eigen::Vector3d rho = R_bp * p.site_from_anchor_m;
  const Eigen::Vector3d r = p.anchor_box_m + rho;
  const Eigen::Vector3d rho_dot = rate_radps * axis.cross(rho);
  const Eigen::Vector3d rho_ddot = accel_radps2 * axis.cross(rho) + rate_radps * axis.cross(rho_dot);
  const Eigen::Matrix3d R_enu_from_body = base.q_enu_from_body.normalized().toRotationMatrix();
  const Eigen::Vector3d a_site_box = R_enu_from_body.transpose() * (base.a_enu_mps2 - gravity_enu_mps2_) +
                                     dw.cross(r) + w.cross(w.cross(r)) + 2.0 * w.cross(rho_dot) + rho_ddot;
  SiteMotion out;
  out.w_radps = R_box_from_site.transpose() * (w + rate_radps * axis);
  out.f_mps2 = R_box_from_site.transpose() * a_site_box;
  out.R_body_from_sensor = R_box_from_site;
  return out;
}

double World::rest_hinge_torque_nm(int i, const MotionState& base, double angle_rad) const {
  const Platform& p = plat_[i - 1];
  const Eigen::Matrix3d R_bp = R_box_from_plat(i, angle_rad);
  const Eigen::Vector3d& w = base.w_body_radps;
  const Eigen::Vector3d& dw = base.dw_body_radps2;
  const Eigen::Vector3d c = R_bp * p.com_from_anchor_m;
  const Eigen::Matrix3d I = R_bp * p.inertia_com_kgm2 * R_bp.transpose();
  const Eigen::Vector3d r_com = p.anchor_box_m + c;
  const Eigen::Matrix3d R_enu_from_body = base.q_enu_from_body.normalized().toRotationMatrix();
  const Eigen::Vector3d a_com = R_enu_from_body.transpose() * (base.a_enu_mps2 - gravity_enu_mps2_) +
                                dw.cross(r_com) + w.cross(w.cross(r_com));
  const Eigen::Vector3d torque = I * dw + w.cross(I * w) + p.mass_kg * c.cross(a_com);
  return (p.R_box_from_plat0 * p.axis_plat).dot(torque);
}

double World::motor_rest_torque_nm(double ref_rad, double angle_rad) const {
  const MotorParams& m = box_.motor;
  return std::clamp(m.kp_nm_per_rad * (ref_rad - angle_rad), -m.stall_torque_nm, m.stall_torque_nm);
}

int World::id(int type, const char* name) const {
  const int i = mj_name2id(model_.get(), type, name);
  if (i < 0) throw std::logic_error(std::string("box model: no element named '") + name + "'");
  return i;
}

double World::platform_angle_rad(int i) const { return data_->qpos[qadr_hinge_[i - 1]]; }
double World::platform_rate_radps(int i) const { return data_->qvel[vadr_hinge_[i - 1]]; }
double World::platform_accel_radps2(int i) const { return data_->qacc[vadr_hinge_[i - 1]]; }

void World::set_platform(int i, double angle_rad, double rate_radps) {
  data_->qpos[qadr_hinge_[i - 1]] = angle_rad;
  data_->qvel[vadr_hinge_[i - 1]] = rate_radps;
}

void World::set_motor_reference(int i, double ref_rad) { data_->ctrl[act_motor_[i - 1]] = ref_rad; }

void World::set_base(const Eigen::Vector3d& p_enu_m, const Eigen::Quaterniond& q_enu_from_body,
                     const Eigen::Vector3d& v_enu_mps, const Eigen::Vector3d& w_body_radps) {
  mjtNum* q = data_->qpos + qadr_drive_;
  mjtNum* v = data_->qvel + vadr_drive_;
  for (int k = 0; k < 3; ++k) {
    q[k] = p_enu_m[k];
    v[k] = v_enu_mps[k];
    v[3 + k] = w_body_radps[k];  // ball joint velocity: angular rate in the child (box) frame
  }
  quat_to_mj(q_enu_from_body.normalized(), q + 3);
}

void World::drive_base(const Eigen::Vector3d& a_enu_mps2, const Eigen::Vector3d& dw_body_radps2) {
  const mjModel* m = model_.get();
  mjData* d = data_.get();
  // drive force = M qacc_ref + bias on the 6 drive dofs (qM holds the drive armature A, so the
  // drive row reads (M_bb + A) qacc_b + M_bp qacc_p = M_bb a + A a: qacc_b = a - M_bp qacc_p / A,
  // i.e. the platforms' reaction on the box moves it by ~1e-9 rad/s^2 at most)
  std::vector<mjtNum>& qacc_ref = scratch_qacc_;
  std::vector<mjtNum>& res = scratch_res_;
  std::fill(qacc_ref.begin(), qacc_ref.end(), 0.0);
  for (int k = 0; k < 3; ++k) {
    qacc_ref[static_cast<std::size_t>(vadr_drive_ + k)] = a_enu_mps2[k];
    qacc_ref[static_cast<std::size_t>(vadr_drive_ + 3 + k)] = dw_body_radps2[k];
  }
  mj_mulM(m, d, res.data(), qacc_ref.data());
  for (int k = 0; k < 6; ++k) {
    const int dof = vadr_drive_ + k;
    d->qfrc_applied[dof] = res[static_cast<std::size_t>(dof)] + d->qfrc_bias[dof];
  }
}

HingeState World::step_driven(double t_s, const MotionState& base, const Eigen::Vector2d& ref_rad,
                               bool sensors) {
  mjModel* m = model_.get();
  mjData* d = data_.get();
  set_base(base.p_enu_m, base.q_enu_from_body, base.v_enu_mps, base.w_body_radps);
  set_motor_reference(1, ref_rad[0]);
  set_motor_reference(2, ref_rad[1]);
  if (!sensors) m->opt.disableflags |= mjDSBL_SENSOR;
  d->time = t_s;
  mj_step1(m, d);  // kinematics, velocities, gyro sensors at t
  drive_base(base.a_enu_mps2, base.dw_body_radps2);
  HingeState h;
  for (int i = 0; i < 2; ++i) {
    h.angle_rad[i] = d->qpos[qadr_hinge_[i]];
    h.rate_radps[i] = d->qvel[vadr_hinge_[i]];
  }
  mj_step2(m, d);  // actuation, constraints (end stops), accelerometers at t; integrate to t + dt
  m->opt.disableflags &= ~mjDSBL_SENSOR;
  return h;
}

Eigen::Vector3d World::mj_gyro(int i) const {
  const mjtNum* s = data_->sensordata + sadr_gyro_[i - 1];
  return {s[0], s[1], s[2]};
}

Eigen::Vector3d World::mj_accel(int i) const {
  const mjtNum* s = data_->sensordata + sadr_accel_[i - 1];
  return {s[0], s[1], s[2]};
}

Eigen::Matrix3d World::R_enu_from_sensor(int i) const {
  const mjtNum* x = data_->site_xmat + 9 * site_imu_[i - 1];
  Eigen::Matrix3d R;
  R << x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7], x[8];
  return R;
}

Eigen::Vector3d World::pan_tilt_axis_enu_m() { return {0, 0, 0.71}; }
Eigen::Vector3d World::box_on_tilt_head_m() { return {0, 0, 0.062}; }
Eigen::Vector3d World::box_on_vehicle_m() { return {-0.1, 0, 1.25}; }
Eigen::Vector3d World::box_on_ship_m() { return {2.5, 0, 0.6}; }

void World::set_visible(int body_id, bool visible) {
  const mjModel* m = model_.get();
  for (int g = 0; g < m->ngeom; ++g) {
    if (m->geom_bodyid[g] == body_id) {
      model_->geom_rgba[4 * g + 3] = visible ? geom_alpha_[static_cast<std::size_t>(g)] : 0.0f;
    }
  }
}

void World::pose_carrier(Carrier c, const Eigen::Vector3d& p_enu_m,
                         const Eigen::Quaterniond& q_enu_from_body) {
  if (scope_ == ModelScope::physics) {
    if (c == Carrier::none) return;
    throw std::logic_error("World: a physics-scope model has no carriers to pose");
  }
  mjData* d = data_.get();
  const Eigen::Quaterniond q = q_enu_from_body.normalized();
  const Eigen::Matrix3d R = q.toRotationMatrix();
  set_visible(body_pan_, c == Carrier::pan_tilt);
  set_visible(body_tilt_, c == Carrier::pan_tilt);
  for (const char* g : {"pt_foot", "pt_column"}) {
    const int gid = id(mjOBJ_GEOM, g);
    model_->geom_rgba[4 * gid + 3] = c == Carrier::pan_tilt ? geom_alpha_[static_cast<std::size_t>(gid)] : 0.0f;
  }
  set_visible(body_vehicle_, c == Carrier::vehicle);
  set_visible(body_ship_, c == Carrier::ship);
  auto put = [&](int mocap, const Eigen::Vector3d& p, const Eigen::Quaterniond& qq) {
    for (int k = 0; k < 3; ++k) d->mocap_pos[3 * mocap + k] = p[k];
    quat_to_mj(qq, d->mocap_quat + 4 * mocap);
  };
  if (c == Carrier::pan_tilt) {
    // the yoke frame is R_enu_from_yoke = Rz(pan) Rx(tilt); the box sits on it (any mount rotation
    // is shown as part of the yoke, an approximation for the picture only)
    const double pan = std::atan2(R(1, 0), R(0, 0));
    const Eigen::Quaterniond q_pan(Eigen::AngleAxisd(pan, Eigen::Vector3d::UnitZ()));
    const Eigen::Vector3d p_axis = pan_tilt_axis_enu_m();
    put(mocap_pan_, Eigen::Vector3d(p_axis.x(), p_axis.y(), 0.51), q_pan);
    put(mocap_tilt_, p_axis, q);
  } else if (c == Carrier::vehicle) {
    put(mocap_vehicle_, p_enu_m - R * box_on_vehicle_m(), q);
  } else if (c == Carrier::ship) {
    put(mocap_ship_, p_enu_m - R * box_on_ship_m(), q);
  }
}

void World::pose(const Eigen::Vector3d& p_enu_m, const Eigen::Quaterniond& q_enu_from_body,
                 double plat1_rad, double plat2_rad, Carrier c) {
  set_base(p_enu_m, q_enu_from_body, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero());
  set_platform(1, plat1_rad);
  set_platform(2, plat2_rad);
  pose_carrier(c, p_enu_m, q_enu_from_body);
  mj_forward(model_.get(), data_.get());
}

}  // namespace driftless::twin
