#include "renders/pose.hpp"

#include <cmath>
#include <stdexcept>
#include <vector>

#include <fmt/core.h>

namespace driftless::render {

void kinematics_for_drawing(const mjModel* m, mjData* d) {
  mj_kinematics(m, d);
  mj_comPos(m, d);
  mj_camlight(m, d);
}

void keep_ground_under(const mjModel* m, mjData* d, int body) {
  if (body < 0) return;
  for (int g = 0; g < m->ngeom; ++g) {
    if (m->geom_type[g] != mjGEOM_PLANE || m->geom_bodyid[g] != 0) continue;
    // only a level plane whose texture runs along the world's x and y
    if (std::abs(d->geom_xmat[9 * g + 8] - 1.0) > 1e-9 || std::abs(d->geom_xmat[9 * g] - 1.0) > 1e-9) continue;
    // a textured plane repeats its texture texrepeat times across its 2 x size extent
    const int mat = m->geom_matid[g];
    for (int k = 0; k < 2; ++k) {
      const double reps = mat >= 0 && m->mat_texrepeat[2 * mat + k] > 0 ? m->mat_texrepeat[2 * mat + k] : 1.0;
      const double period = 2.0 * m->geom_size[3 * g + k] / reps;
      if (!(period > 0.0)) continue;
      const double shift = period * std::round((d->xpos[3 * body + k] - m->geom_pos[3 * g + k]) / period);
      d->geom_xpos[3 * g + k] = m->geom_pos[3 * g + k] + shift;
    }
  }
}

BoxPoser::BoxPoser(const mjModel* m, const std::string& base_body, const std::string& plat1_joint,
                   const std::string& plat2_joint)
    : m_(m), d_(nullptr, &mj_deleteData) {
  if (m == nullptr) throw std::invalid_argument("BoxPoser needs a model");
  const int body = mj_name2id(m, mjOBJ_BODY, base_body.c_str());
  if (body < 0) {
    throw std::invalid_argument(
        fmt::format("the model has no body '{}' to pose from ref_p/ref_q", base_body));
  }
  for (int j = m->body_jntadr[body]; j >= 0 && j < m->body_jntadr[body] + m->body_jntnum[body];
       ++j) {
    switch (m->jnt_type[j]) {
      case mjJNT_FREE: free_adr_ = m->jnt_qposadr[j]; break;
      case mjJNT_BALL: ball_adr_ = m->jnt_qposadr[j]; break;
      case mjJNT_SLIDE: slides_.emplace_back(m->jnt_qposadr[j], j); break;
      default: break;
    }
  }
  const std::string names[2] = {plat1_joint, plat2_joint};
  for (int i = 0; i < 2; ++i) {
    const int j = mj_name2id(m, mjOBJ_JOINT, names[i].c_str());
    if (j < 0 || m->jnt_type[j] != mjJNT_HINGE) {
      throw std::invalid_argument(
          fmt::format("the model has no hinge joint '{}' for platform {}", names[i], i + 1));
    }
    plat_adr_[i] = m->jnt_qposadr[j];
  }
  bodies_ = find_framed_bodies(m, base_body.c_str(), plat1_joint.c_str(), plat2_joint.c_str());
  d_.reset(mj_makeData(m));
  kinematics_for_drawing(m, d_.get());
}

void BoxPoser::pose(const Sample& s) {
  const mjModel* m = m_;
  mjtNum* q = d_->qpos;
  const bool has_p = s.ref_p_enu_m.allFinite();
  Eigen::Vector4d qwxyz = s.ref_q_wxyz;
  const bool has_q = qwxyz.allFinite() && qwxyz.norm() > 0.5;
  if (has_q) qwxyz.normalize();
  if (free_adr_ >= 0) {
    if (has_p) {
      for (int k = 0; k < 3; ++k) q[free_adr_ + k] = s.ref_p_enu_m[k];
    }
    if (has_q) {
      for (int k = 0; k < 4; ++k) q[free_adr_ + 3 + k] = qwxyz[k];
    }
  }
  if (has_p) {
    // slides along world axes take the position's component along their axis
    for (const auto& [adr, j] : slides_) {
      const mjtNum* a = m->jnt_axis + 3 * j;
      q[adr] = a[0] * s.ref_p_enu_m[0] + a[1] * s.ref_p_enu_m[1] + a[2] * s.ref_p_enu_m[2];
    }
  }
  if (ball_adr_ >= 0 && has_q) {
    for (int k = 0; k < 4; ++k) q[ball_adr_ + k] = qwxyz[k];
  }
  const double plat_deg[2] = {std::isfinite(s.true_plat1_deg) ? s.true_plat1_deg : s.plat1_deg,
                              std::isfinite(s.true_plat2_deg) ? s.true_plat2_deg : s.plat2_deg};
  for (int i = 0; i < 2; ++i) {
    if (std::isfinite(plat_deg[i])) q[plat_adr_[i]] = plat_deg[i] * kRadPerDeg;
  }
  kinematics_for_drawing(m, d_.get());
  keep_ground_under(m, d_.get(), bodies_.box);
}

}  // namespace driftless::render
