// Where the camera looks: a camera that frames the box so it fills most of the picture, follows
// it on a moving carrier, and closes in on a platform while it flips (docs/render.md, "Camera").
// The geometry (fitting points into a perspective view) is separate from MuJoCo so it can be
// checked against closed forms.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <mujoco/mujoco.h>

namespace driftless::render {

/// Direction of view in MuJoCo's free-camera convention: forward = (cos el cos az,
/// cos el sin az, sin el) in world axes (ENU); elevation < 0 looks down. Degrees.
struct ViewAngles {
  double azimuth_deg = 60.0;
  double elevation_deg = -38.0;
};

/// The camera's right, up and forward unit vectors (world axes) for `v`.
struct CameraAxes {
  Eigen::Vector3d right, up, forward;
};
CameraAxes camera_axes(const ViewAngles& v);

/// A free camera: it sits at lookat - distance * forward and looks along forward.
struct CameraFraming {
  Eigen::Vector3d lookat_m = Eigen::Vector3d::Zero();
  double distance_m = 1.0;
};

/// The closest camera looking along `v` that shows every point inside the central `fill`
/// fraction (0..1] of a viewport of vertical field of view `fovy_deg` and width/height
/// `aspect`: |x_ndc| <= fill and |y_ndc| <= fill for each point. The lookat is the centre of the
/// points' extent across the view. Needs at least one point.
CameraFraming frame_points(const std::vector<Eigen::Vector3d>& points_world, const ViewAngles& v,
                           double fovy_deg, double aspect, double fill);

/// Corners (world, m) of the axis-aligned boxes that bound each visible geom of `body` and its
/// descendants in the geom's own frame (boxes exactly; capsules, cylinders, ellipsoids by their
/// extents; other shapes by their bounding sphere). Geoms with alpha 0 or outside the geom groups
/// that `opt` shows are skipped; planes never count.
std::vector<Eigen::Vector3d> body_corners_world(const mjModel* m, const mjData* d, int body,
                                                const mjvOption& opt);

/// The bodies a frame is built around: the box (base) and its two platforms; -1 when absent.
struct FramedBodies {
  int box = -1;
  int platform[2] = {-1, -1};
};
/// Finds the base body by name and each platform as the body of its hinge joint.
FramedBodies find_framed_bodies(const mjModel* m, const char* base_body = "box",
                                const char* hinge1 = "hinge1", const char* hinge2 = "hinge2");

/// The view angles of a camera looking along `forward` (world axes, any length).
ViewAngles view_angles(const Eigen::Vector3d& forward);

/// Chooses the free camera frame by frame: the box filling `box_fill` of the view, or, while
/// update() names a platform, that platform (the sphere it sweeps) filling `closeup_fill`, seen
/// mostly along its hinge axis: a platform turns its board within the board's plane, so the
/// turn shows best face-on. Changes of subject are blended over `blend_frames` frames so the
/// view never jumps.
class CameraDirector {
 public:
  struct Params {
    ViewAngles view;
    double box_fill = 0.94;     // fraction of the view the box's extent spans (NDC)
    double closeup_fill = 0.8;  // the same for a platform in close-up
    int blend_frames = 9;       // frames to move between the box and a close-up
  };
  CameraDirector(const mjModel* m, const FramedBodies& bodies, const Params& p);

  /// The camera for the next frame; `close_up`: platform 0/1 to show large, -1 for the box.
  /// `aspect`: viewport width / height.
  void update(const mjData* d, const mjvOption& opt, int close_up, double aspect, mjvCamera* cam);
  /// Blend state: 0 = box framing, 1 = fully in close-up (for tests and the overlay).
  double close_up_weight() const { return weight_; }
  int close_up_platform() const { return platform_; }

 private:
  CameraFraming box_framing(const mjData* d, const mjvOption& opt, double aspect) const;
  ViewAngles platform_view(const mjData* d, int platform) const;
  CameraFraming platform_framing(const mjData* d, const mjvOption& opt, int platform, const ViewAngles& v,
                                 double aspect) const;

  const mjModel* m_;
  FramedBodies bodies_;
  Params p_;
  double fovy_deg_;
  double weight_ = 0.0;  // 0 = box, 1 = platform_
  int platform_ = -1;    // the platform the close-up shows (kept while blending out)
  double box_distance_m_ = -1.0;  // smoothed box framing distance (the box turns on its carrier)
};

}  // namespace driftless::render
