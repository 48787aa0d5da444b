// Posing the world for a frame: a WorldPoser owns the model's mjData and places the box, its
// platforms and its carrier from a Sample (ref_p, ref_q, platform angles).
#pragma once

#include <memory>
#include <string>

#include <mujoco/mujoco.h>

#include "estimator/sample.hpp"
#include "renders/framing.hpp"

namespace driftless::render {

/// Places the world from a sample and computes what drawing needs (body, site, camera frames).
class WorldPoser {
 public:
  virtual ~WorldPoser() = default;
  virtual const mjModel* model() const = 0;
  virtual mjData* data() = 0;
  /// Poses the world for `s` (angles in deg as logged; NaN parts keep their previous pose).
  virtual void pose(const Sample& s) = 0;
  /// The box and platform bodies (for the framing camera).
  virtual FramedBodies bodies() const = 0;
};

/// Poses a model whose base body carries either a free joint or slide joints plus a ball joint
/// (ENU position ref_p, attitude ref_q = q_enu_from_body) and whose platforms turn on hinge
/// joints (true_plat*_deg if present, else plat*_deg). Other joints and mocap bodies keep the
/// model's reference pose. Works with any such MJCF (tests, user models).
class BoxPoser final : public WorldPoser {
 public:
  /// base_body: the box body; plat joints: the hinges. Throws std::invalid_argument naming what
  /// is missing. `model` must outlive the poser.
  explicit BoxPoser(const mjModel* model, const std::string& base_body = "box",
                    const std::string& plat1_joint = "hinge1",
                    const std::string& plat2_joint = "hinge2");
  const mjModel* model() const override { return m_; }
  mjData* data() override { return d_.get(); }
  void pose(const Sample& s) override;
  FramedBodies bodies() const override { return bodies_; }

 private:
  const mjModel* m_;
  FramedBodies bodies_;
  std::unique_ptr<mjData, decltype(&mj_deleteData)> d_;
  int free_adr_ = -1;                        // qpos address of the base's free joint
  std::vector<std::pair<int, int>> slides_;  // (qpos address, joint id) of base slides
  int ball_adr_ = -1;
  int plat_adr_[2] = {-1, -1};
};

/// Computes positions for drawing from qpos/mocap: kinematics, subtree centres (tracking
/// cameras) and cameras/lights; cheaper than mj_forward.
void kinematics_for_drawing(const mjModel* m, mjData* d);

/// Moves the drawn ground planes (planes of the world body) under `body` by whole periods of
/// their texture, so a box carried kilometres away (vehicle, ship) still has the ground below it
/// and the pattern stays fixed to the world. Changes only mjData's drawing positions.
void keep_ground_under(const mjModel* m, mjData* d, int body);

}  // namespace driftless::render
