// Flip replay on a static box (docs/model.md, "How the simulator saves time"). With the box at
// rest, a flip is the same motion every time it starts from the same rest: the box, gravity and
// the servo are time-invariant, and the other platform rests on a driven box that does not pass
// the flip's reaction on. So MuJoCo steps the first flip of each kind (platform, direction) and
// later flips of that kind replay its recorded hinge trajectory; the truth then comes from the
// site kinematics (World::site_motion), as on the rest path.
#pragma once

#include <optional>
#include <vector>

namespace driftless::twin {

class FlipReplay {
 public:
  /// The moving platform's hinge at the start of one physics step.
  struct Step {
    double angle_rad, rate_radps, accel_radps2;
  };
  /// A recorded flip: platform i (1 or 2) from its rest at `start_angle_rad` toward `sign`,
  /// one Step per physics step, the last one where the simulator came to rest.
  struct Flip {
    int platform = 0;
    int sign = 0;
    double start_angle_rad = 0;
    std::vector<Step> steps;
  };

  /// Starts recording a flip of platform i toward `sign` from rest at `start_angle_rad`.
  void start_recording(int i, int sign, double start_angle_rad);
  /// Adds the moving platform's hinge state of one step (no-op when not recording).
  void record(const Step& s);
  /// Ends the recording: kept (replacing an older flip of its kind) when the flip came to rest,
  /// dropped when it was cut short (another command, the end of the run).
  void stop_recording(bool came_to_rest);
  bool recording() const { return recording_.has_value(); }
  /// The platform being recorded (1 or 2; 0 when not recording).
  int recording_platform() const { return recording_ ? recording_->platform : 0; }
  int recording_sign() const { return recording_ ? recording_->sign : 0; }

  /// The recorded flip of platform i toward `sign` that started at `start_angle_rad` (the rest
  /// angles agree to 1e-9 rad, far below anything the truth can show), or null.
  const Flip* find(int i, int sign, double start_angle_rad) const;

 private:
  std::vector<Flip> flips_;        // at most 4: two platforms, two directions
  std::optional<Flip> recording_;
};

}  // namespace driftless::twin
