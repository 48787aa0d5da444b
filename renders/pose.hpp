// The world's pose for one frame (joint positions and mocap carriers), and posing the model's
// box from a logged Sample (ref_p, ref_q, plat*_deg) for replays of logs without a simulator.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <mujoco/mujoco.h>

#include "estimator/sample.hpp"

namespace driftless::render {

/// Everything a frame needs to place bodies: mjData's qpos, mocap_pos and mocap_quat.
struct WorldPose {
  std::vector<mjtNum> qpos, mocap_pos, mocap_quat;

  /// Copies the pose out of `d`.
  void capture(const mjModel* m, const mjData* d);
  /// Writes the pose into `d` and computes positions for drawing (kinematics, com, cameras).
  void apply(const mjModel* m, mjData* d) const;
};

/// Poses the world from a Sample; implementations know the model's joints and carriers.
using PoseFn = std::function<void(const Sample& s, WorldPose& out)>;

/// Poses a model whose base body carries either a free joint or slide joints plus a ball joint
/// (ENU position ref_p, attitude ref_q = q_enu_from_body) and whose platforms turn on hinge
/// joints (plat1_deg, plat2_deg). Other joints and mocap bodies keep the model's reference pose.
class BoxPoser {
 public:
  /// base_body: the box body ("box"); plat joints: the hinges ("hinge1", "hinge2"). Throws
  /// std::invalid_argument naming what is missing.
  explicit BoxPoser(const mjModel* m, const std::string& base_body = "box",
                    const std::string& plat1_joint = "hinge1",
                    const std::string& plat2_joint = "hinge2");
  /// Fills `out` for sample `s`; NaN parts (no ref_p, no ref_q, a moving platform) keep the
  /// reference pose or, for a platform, its last angle.
  void pose(const Sample& s, WorldPose& out) const;

 private:
  const mjModel* m_;
  int free_adr_ = -1;                 // qpos address of the base's free joint
  std::vector<std::pair<int, int>> slides_;  // (qpos address, joint id) of base slides
  int ball_adr_ = -1;
  int plat_adr_[2] = {-1, -1};
};

}  // namespace driftless::render
