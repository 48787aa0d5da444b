#include "renders/framing.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "estimator/sample.hpp"

namespace driftless::render {

namespace {
constexpr double kMaxCloseUpElevationDeg = -30.0;  // deg, close-ups look at least this far down
}  // namespace

CameraAxes camera_axes(const ViewAngles& v) {
  const double az = v.azimuth_deg * kRadPerDeg, el = v.elevation_deg * kRadPerDeg;
  CameraAxes a;
  a.forward = Eigen::Vector3d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
  a.up = Eigen::Vector3d(-std::sin(el) * std::cos(az), -std::sin(el) * std::sin(az), std::cos(el));
  a.right = a.forward.cross(a.up);
  return a;
}

CameraFraming frame_points(const std::vector<Eigen::Vector3d>& pts, const ViewAngles& v, double fovy_deg,
                           double aspect, double fill) {
  if (pts.empty()) throw std::invalid_argument("frame_points needs at least one point");
  const CameraAxes ax = camera_axes(v);
  // centre of the points' extent along the camera's axes
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (const auto& p : pts) {
    const Eigen::Vector3d c(p.dot(ax.right), p.dot(ax.up), p.dot(ax.forward));
    lo = lo.cwiseMin(c);
    hi = hi.cwiseMax(c);
  }
  const Eigen::Vector3d mid = 0.5 * (lo + hi);
  CameraFraming f;
  f.lookat_m = mid.x() * ax.right + mid.y() * ax.up + mid.z() * ax.forward;
  // a point q (from the lookat) at depth d + q.f shows at y_ndc = (q.u) / ((d + q.f) tan(fovy/2)):
  // |y_ndc| <= fill needs d >= |q.u| / (fill tan(fovy/2)) - q.f, and the same across
  const double ty = fill * std::tan(0.5 * fovy_deg * kRadPerDeg);
  const double tx = ty * aspect;
  double d = 0.0;
  for (const auto& p : pts) {
    const Eigen::Vector3d q = p - f.lookat_m;
    const double depth = q.dot(ax.forward);
    d = std::max({d, std::abs(q.dot(ax.up)) / ty - depth, std::abs(q.dot(ax.right)) / tx - depth,
                  1e-3 - depth});
  }
  f.distance_m = d;
  return f;
}

namespace {

bool in_subtree(const mjModel* m, int body, int root) {
  for (int b = body; b > 0; b = m->body_parentid[b]) {
    if (b == root) return true;
  }
  return root == 0;
}

// half extents of a geom's bounding box in its own frame, m
Eigen::Vector3d geom_half_extents(const mjModel* m, int g) {
  const mjtNum* s = m->geom_size + 3 * g;
  switch (m->geom_type[g]) {
    case mjGEOM_BOX:
    case mjGEOM_ELLIPSOID: return {s[0], s[1], s[2]};
    case mjGEOM_CAPSULE: return {s[0], s[0], s[1] + s[0]};
    case mjGEOM_CYLINDER: return {s[0], s[0], s[1]};
    case mjGEOM_SPHERE: return Eigen::Vector3d::Constant(s[0]);
    default: return Eigen::Vector3d::Constant(m->geom_rbound[g]);
  }
}

}  // namespace

std::vector<Eigen::Vector3d> body_corners_world(const mjModel* m, const mjData* d, int body,
                                                const mjvOption& opt) {
  std::vector<Eigen::Vector3d> out;
  if (body < 0) return out;
  for (int g = 0; g < m->ngeom; ++g) {
    if (m->geom_type[g] == mjGEOM_PLANE || m->geom_type[g] == mjGEOM_HFIELD) continue;
    if (m->geom_rgba[4 * g + 3] <= 0.0f) continue;
    const int group = std::clamp(m->geom_group[g], 0, mjNGROUP - 1);
    if (opt.geomgroup[group] == 0) continue;
    if (!in_subtree(m, m->geom_bodyid[g], body)) continue;
    const Eigen::Vector3d h = geom_half_extents(m, g);
    const Eigen::Map<const Eigen::Vector3d> pos(d->geom_xpos + 3 * g);
    // geom_xmat is row-major: the rows of the map below are the world axes, its columns the geom's
    const Eigen::Map<const Eigen::Matrix<mjtNum, 3, 3, Eigen::RowMajor>> R(d->geom_xmat + 9 * g);
    for (int k = 0; k < 8; ++k) {
      const Eigen::Vector3d c((k & 1) ? h.x() : -h.x(), (k & 2) ? h.y() : -h.y(), (k & 4) ? h.z() : -h.z());
      out.push_back(pos + R * c);
    }
  }
  return out;
}

FramedBodies find_framed_bodies(const mjModel* m, const char* base_body, const char* hinge1, const char* hinge2) {
  FramedBodies b;
  b.box = mj_name2id(m, mjOBJ_BODY, base_body);
  const char* hinges[2] = {hinge1, hinge2};
  for (int i = 0; i < 2; ++i) {
    const int j = mj_name2id(m, mjOBJ_JOINT, hinges[i]);
    b.platform[i] = j >= 0 ? m->jnt_bodyid[j] : -1;
  }
  return b;
}

CameraDirector::CameraDirector(const mjModel* m, const FramedBodies& bodies, const Params& p)
    : m_(m), bodies_(bodies), p_(p), fovy_deg_(m->vis.global.fovy) {
  if (!(p.box_fill > 0.0 && p.box_fill <= 1.0) || !(p.closeup_fill > 0.0 && p.closeup_fill <= 1.0)) {
    throw std::invalid_argument("camera fill fractions must be in (0, 1]");
  }
  if (p.blend_frames < 1) throw std::invalid_argument("camera blend needs at least 1 frame");
}

CameraFraming CameraDirector::box_framing(const mjData* d, const mjvOption& opt, double aspect) const {
  auto pts = body_corners_world(m_, d, bodies_.box >= 0 ? bodies_.box : 0, opt);
  if (pts.empty()) pts.push_back(Eigen::Vector3d::Zero());
  return frame_points(pts, p_.view, fovy_deg_, aspect, p_.box_fill);
}

ViewAngles view_angles(const Eigen::Vector3d& forward) {
  const Eigen::Vector3d f = forward.normalized();
  const double el = std::asin(std::clamp(f.z(), -1.0, 1.0)) * kDegPerRad;
  return {std::atan2(f.y(), f.x()) * kDegPerRad, std::clamp(el, -85.0, 85.0)};
}

// look mostly along the hinge axis, a quarter of the way towards the box camera's direction (so
// the close-up keeps some depth and the cut feels continuous), from outside: when the hinge axis
// points away from the box's middle the camera sits beyond the platform, where nothing of the
// box stands in front of it; otherwise on the box camera's side. Never above 30 deg below the
// horizon: the sky is not drawn
ViewAngles CameraDirector::platform_view(const mjData* d, int platform) const {
  const Eigen::Vector3d f_box = camera_axes(p_.view).forward;
  const int body = bodies_.platform[platform];
  const int jnt = m_->body_jntadr[body];
  if (jnt < 0) return p_.view;
  Eigen::Vector3d a = Eigen::Map<const Eigen::Vector3d>(d->xaxis + 3 * jnt).normalized();
  const Eigen::Vector3d out = Eigen::Map<const Eigen::Vector3d>(d->xpos + 3 * body) -
                              Eigen::Map<const Eigen::Vector3d>(d->xipos + 3 * std::max(bodies_.box, 0));
  const bool outside = std::abs(a.dot(out)) > 0.2 * out.norm();
  if (outside ? a.dot(out) > 0.0 : a.dot(f_box) < 0.0) a = -a;
  ViewAngles v = view_angles(0.75 * a + 0.25 * f_box);
  v.elevation_deg = std::min(v.elevation_deg, kMaxCloseUpElevationDeg);
  return v;
}

// the platform turns about its hinge: frame the sphere it sweeps (the same size at every angle,
// so the close-up does not zoom while the platform turns)
CameraFraming CameraDirector::platform_framing(const mjData* d, const mjvOption& opt, int platform,
                                               const ViewAngles& v, double aspect) const {
  const int body = bodies_.platform[platform];
  const Eigen::Map<const Eigen::Vector3d> centre(d->xpos + 3 * body);
  double r = 0.0;
  for (const auto& p : body_corners_world(m_, d, body, opt)) r = std::max(r, (p - centre).norm());
  if (r <= 0.0) r = m_->stat.extent / 20.0;
  const CameraAxes ax = camera_axes(v);
  std::vector<Eigen::Vector3d> pts;
  for (const Eigen::Vector3d& a : {ax.right, ax.up, ax.forward}) {
    pts.push_back(centre + r * a);
    pts.push_back(centre - r * a);
  }
  return frame_points(pts, v, fovy_deg_, aspect, p_.closeup_fill);
}

void CameraDirector::update(const mjData* d, const mjvOption& opt, int close_up, double aspect, mjvCamera* cam) {
  if (close_up >= 0 && (close_up > 1 || bodies_.platform[close_up] < 0)) close_up = -1;
  // move the blend weight towards the wanted subject; a change of platform goes through the box
  const double step = 1.0 / p_.blend_frames;
  if (close_up >= 0 && (platform_ < 0 || platform_ == close_up || weight_ <= 0.0)) {
    platform_ = close_up;
    weight_ = std::min(1.0, weight_ + step);
  } else {
    weight_ = std::max(0.0, weight_ - step);
    if (weight_ <= 0.0) platform_ = close_up;
  }
  CameraFraming box = box_framing(d, opt, aspect);
  // the box turns on its carrier and its extent with it: ease the distance, never the position
  if (box_distance_m_ > 0.0) box.distance_m = box_distance_m_ + 0.25 * (box.distance_m - box_distance_m_);
  box_distance_m_ = box.distance_m;
  CameraFraming f = box;
  ViewAngles v = p_.view;
  if (weight_ > 0.0 && platform_ >= 0) {
    const ViewAngles vn = platform_view(d, platform_);
    const CameraFraming near = platform_framing(d, opt, platform_, vn, aspect);
    const double s = weight_ * weight_ * (3.0 - 2.0 * weight_);  // smoothstep
    f.lookat_m = (1.0 - s) * box.lookat_m + s * near.lookat_m;
    f.distance_m = std::exp((1.0 - s) * std::log(box.distance_m) + s * std::log(near.distance_m));
    // turn the short way round
    const double daz = std::remainder(vn.azimuth_deg - v.azimuth_deg, 360.0);
    v = {v.azimuth_deg + s * daz, v.elevation_deg + s * (vn.elevation_deg - v.elevation_deg)};
  }
  cam->type = mjCAMERA_FREE;
  for (int k = 0; k < 3; ++k) cam->lookat[k] = f.lookat_m[k];
  cam->distance = f.distance_m;
  cam->azimuth = v.azimuth_deg;
  cam->elevation = v.elevation_deg;
}

}  // namespace driftless::render
