// GIVEN points (or a model's box) WHEN the framing camera is placed THEN MuJoCo's own camera
// shows them exactly at the wanted fill of the view; the director closes in on a platform and
// backs out in the set number of frames.
#include <cmath>

#include <gtest/gtest.h>

#include "renders/framing.hpp"
#include "renders/pose.hpp"
#include "tests/renders/render_fixture.hpp"

namespace driftless::render {
namespace {

using testing::load_model;

// the largest |NDC| (x or y) of the points seen by MuJoCo's camera built from `cam`
double max_ndc(const mjModel* m, mjData* d, const mjvCamera& cam, const std::vector<Eigen::Vector3d>& pts,
               double aspect) {
  mjvScene scn;
  mjv_defaultScene(&scn);
  mjv_makeScene(m, &scn, 100);
  mjvOption opt;
  mjv_defaultOption(&opt);
  mjvCamera c = cam;
  mjv_updateScene(m, d, &opt, nullptr, &c, mjCAT_ALL, &scn);
  // the two cameras are the stereo eyes; a mono frame is drawn from their average
  const mjvGLCamera g = mjv_averageCamera(&scn.camera[0], &scn.camera[1]);
  const Eigen::Vector3d pos(g.pos[0], g.pos[1], g.pos[2]), fwd(g.forward[0], g.forward[1], g.forward[2]),
      up(g.up[0], g.up[1], g.up[2]);
  const Eigen::Vector3d right = fwd.cross(up);
  const double half_h = 0.5 * (g.frustum_top - g.frustum_bottom);
  double worst = 0.0;
  for (const auto& p : pts) {
    const Eigen::Vector3d v = p - pos;
    const double z = v.dot(fwd);
    worst = std::max({worst, std::abs(v.dot(up) / z * g.frustum_near / half_h),
                      std::abs(v.dot(right) / z * g.frustum_near / (half_h * aspect))});
  }
  mjv_freeScene(&scn);
  return worst;
}

TEST(Framing, CameraAxesFollowMujocosFreeCameraConvention) {
  const CameraAxes a = camera_axes({0.0, 0.0});
  EXPECT_NEAR((a.forward - Eigen::Vector3d::UnitX()).norm(), 0.0, 1e-12);
  EXPECT_NEAR((a.up - Eigen::Vector3d::UnitZ()).norm(), 0.0, 1e-12);
  EXPECT_NEAR((a.right + Eigen::Vector3d::UnitY()).norm(), 0.0, 1e-12);  // looking east, right is south
  const CameraAxes b = camera_axes({60.0, -38.0});
  EXPECT_NEAR(b.forward.norm(), 1.0, 1e-12);
  EXPECT_NEAR(b.forward.dot(b.up), 0.0, 1e-12);
  EXPECT_LT(b.forward.z(), 0.0);  // negative elevation looks down
}

TEST(Framing, ASegmentAcrossTheViewNeedsTheClosedFormDistance) {
  // GIVEN two points 2h apart along the camera's up axis, at the lookat depth
  const ViewAngles v{30.0, -20.0};
  const CameraAxes ax = camera_axes(v);
  const double h = 0.2, fovy = 40.0, fill = 0.8;
  const Eigen::Vector3d c(1.0, 2.0, 0.5);
  const CameraFraming f = frame_points({c + h * ax.up, c - h * ax.up}, v, fovy, 1.5, fill);
  // THEN lookat is their middle and d = h / (fill tan(fovy/2))
  EXPECT_NEAR((f.lookat_m - c).norm(), 0.0, 1e-12);
  EXPECT_NEAR(f.distance_m, h / (fill * std::tan(0.5 * fovy * kRadPerDeg)), 1e-12);
}

TEST(Framing, TheBoxFillsTheWantedFractionOfMujocosView) {
  auto model = load_model();
  BoxPoser poser(model.get());
  Sample s;
  s.plat1_deg = s.plat2_deg = 90.0;
  s.set_q_enu_from_body(Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.2, 0.3, 1.0).normalized())));
  s.ref_p_enu_m = Eigen::Vector3d(3.0, -1.0, 0.4);
  poser.pose(s);
  mjvOption opt;
  mjv_defaultOption(&opt);
  const auto corners = body_corners_world(model.get(), poser.data(), poser.bodies().box, opt);
  ASSERT_GE(corners.size(), 8u);
  for (double aspect : {4.0 / 3.0, 0.8}) {
    const ViewAngles v{60.0, -38.0};
    const CameraFraming f = frame_points(corners, v, model->vis.global.fovy, aspect, 0.9);
    mjvCamera cam;
    mjv_defaultCamera(&cam);
    cam.type = mjCAMERA_FREE;
    for (int k = 0; k < 3; ++k) cam.lookat[k] = f.lookat_m[k];
    cam.distance = f.distance_m;
    cam.azimuth = v.azimuth_deg;
    cam.elevation = v.elevation_deg;
    EXPECT_NEAR(max_ndc(model.get(), poser.data(), cam, corners, aspect), 0.9, 1e-6) << "aspect " << aspect;
  }
}

TEST(Framing, BoxCornersAreTheShellsCorners) {
  // the test box's only geom on the base body is its 0.1 x 0.07 x 0.045 m shell; the platforms'
  // parts lie inside it
  auto model = load_model();
  BoxPoser poser(model.get());
  Sample s;
  s.plat1_deg = s.plat2_deg = 0.0;
  s.set_q_enu_from_body(Eigen::Quaterniond::Identity());
  s.ref_p_enu_m.setZero();
  poser.pose(s);
  mjvOption opt;
  mjv_defaultOption(&opt);
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e9), hi = -lo;
  for (const auto& c : body_corners_world(model.get(), poser.data(), poser.bodies().box, opt)) {
    lo = lo.cwiseMin(c);
    hi = hi.cwiseMax(c);
  }
  EXPECT_NEAR((hi - Eigen::Vector3d(0.1, 0.07, 0.045)).norm(), 0.0, 1e-9);
  EXPECT_NEAR((lo + Eigen::Vector3d(0.1, 0.07, 0.045)).norm(), 0.0, 1e-9);
}

TEST(Framing, TheDirectorClosesInAndBacksOutInTheSetFrames) {
  auto model = load_model();
  BoxPoser poser(model.get());
  Sample s;
  s.plat1_deg = s.plat2_deg = 90.0;
  s.set_q_enu_from_body(Eigen::Quaterniond::Identity());
  s.ref_p_enu_m.setZero();
  poser.pose(s);
  mjvOption opt;
  mjv_defaultOption(&opt);
  CameraDirector::Params p;
  p.blend_frames = 4;
  CameraDirector dir(model.get(), poser.bodies(), p);
  mjvCamera cam;
  mjv_defaultCamera(&cam);
  dir.update(poser.data(), opt, -1, 1.0, &cam);
  const double box_distance = cam.distance;
  // WHEN platform 2 is asked for THEN the camera reaches it in 4 frames, closer than the box
  for (int i = 0; i < 4; ++i) dir.update(poser.data(), opt, 1, 1.0, &cam);
  EXPECT_EQ(dir.close_up_weight(), 1.0);
  EXPECT_EQ(dir.close_up_platform(), 1);
  EXPECT_LT(cam.distance, 0.6 * box_distance);
  const Eigen::Map<const Eigen::Vector3d> plat2(poser.data()->xpos + 3 * poser.bodies().platform[1]);
  EXPECT_NEAR((Eigen::Vector3d(cam.lookat[0], cam.lookat[1], cam.lookat[2]) - plat2).norm(), 0.0, 0.01);
  // platform 2 turns about the box's x axis at the +x end: the camera looks at it from beyond,
  // along -x (nothing of the box in front), and from above
  const Eigen::Vector3d f2 = camera_axes({cam.azimuth, cam.elevation}).forward;
  EXPECT_LT(f2.x(), -0.5);
  EXPECT_LE(cam.elevation, -30.0 + 1e-9);
  // a switch to platform 1 goes through the box: 4 frames out, then in
  for (int i = 0; i < 4; ++i) dir.update(poser.data(), opt, 0, 1.0, &cam);
  EXPECT_EQ(dir.close_up_weight(), 0.0);
  dir.update(poser.data(), opt, 0, 1.0, &cam);
  EXPECT_EQ(dir.close_up_platform(), 0);
  EXPECT_GT(dir.close_up_weight(), 0.0);
  // platform 1 turns about the box's z axis: seen from above, mostly along its axis
  for (int i = 0; i < 4; ++i) dir.update(poser.data(), opt, 0, 1.0, &cam);
  EXPECT_LT(camera_axes({cam.azimuth, cam.elevation}).forward.z(), -0.8);
  // back to the box
  for (int i = 0; i < 4; ++i) dir.update(poser.data(), opt, -1, 1.0, &cam);
  EXPECT_EQ(dir.close_up_weight(), 0.0);
  EXPECT_NEAR(cam.distance, box_distance, 1e-9);
}

}  // namespace
}  // namespace driftless::render
