#include "cli/estimate_health_flip.hpp"

#include "cli/estimate_health.hpp"

#include <cmath>

#include <fmt/format.h>

namespace driftless::cli {
namespace {

using est::HealthCause;

int platform(const est::HealthFinding& f) { return f.components.empty() ? 1 : f.components.front(); }

// "platform 2" or "both platforms"
std::string platforms(const est::HealthFinding& f) {
  return f.components.size() > 1 ? std::string("both platforms") : fmt::format("platform {}", platform(f));
}

// "7 of 14 flips (the first at t = 309.0 s)"
std::string how_many(const est::HealthFinding& f) {
  return fmt::format("{} of {:g} flips of {} (the first at t = {:.1f} s)", f.count, f.suggested, platforms(f), f.sigma);
}

std::string unit_text(const est::HealthFinding& f) {
  switch (f.cause) {
    case HealthCause::kFlipGyroUnit:
      return fmt::format("the gyros integrate each flip to {:.3g}x the angle columns' change (180 deg reads as "
                         "{:.3g}) in {}: the gyro columns are in rad/s? The log wants deg/s: multiply gyro1_* and "
                         "gyro2_* by 57.2958. Every bias, sigma and NIS of this run is off by that factor",
                         f.value, 180.0 * f.value, how_many(f));
    case HealthCause::kFlipAngleUnit:
      return fmt::format("the gyros turned {:.3g}x the change of the angle columns in {} (a 180 deg flip reads "
                         "{:.3g}): plat1_deg/plat2_deg are in radians? The log wants degrees: multiply them by "
                         "57.2958. The positions, and every update built from them, are wrong",
                         f.value, how_many(f), 180.0 / f.value);
    default: {
      const bool us = f.value > 3e4;
      return fmt::format("each flip's integrated gyro rate is {:.3g}x the angle columns' change in {}: the time "
                         "stamps advance {}x too fast; t is in {}? The log wants seconds: divide t by {}. Every "
                         "time, rate and noise figure of this run is off by that factor",
                         f.value, how_many(f), us ? "1e6" : "1000", us ? "microseconds" : "milliseconds",
                         us ? "1e6" : "1000");
    }
  }
}

std::string platform_text(const est::HealthFinding& f, const est::EstimatorConfig& cfg) {
  const int p = platform(f);
  switch (f.cause) {
    case HealthCause::kFlipNotSeen:
      return fmt::format("platform {0}'s gyro turned {1:.0f} % of the change of plat{0}_deg about its hinge in {2}: "
                         "the platform stuck, or its angle column reports the command, not the position; check "
                         "the actuator and the angle read-back (the standstills after such a flip used a position "
                         "the platform was not at)",
                         p, 100.0 * std::fabs(f.value), how_many(f));
    case HealthCause::kFlipAngleSign:
      return fmt::format("platform {0} turned against the sign of plat{0}_deg in {1} (gyro turn / angle change "
                         "{2:.2f}): the angle column counts against the right-hand rule about hinge{0}_axis; "
                         "negate plat{0}_deg (or hinge{0}_axis in the header)",
                         p, how_many(f), f.value);
    case HealthCause::kFlipWrapped:
      return fmt::format("platform {0} turned the same way in every flip, and {1} read the opposite way from "
                         "plat{0}_deg: the angle wraps at +-180 (a platform that turns one way){2}; nothing to do",
                         p, how_many(f),
                         cfg.self_calibration ? ": handled, the self-calibration's flip updates take the angle change "
                                                "modulo 360 with the sign and size the gyros saw"
                                              : " (handled: the standstills use the angle modulo 360)");
    case HealthCause::kFlipSensorsSwapped:
      return fmt::format("in {0} the other sensor's gyro columns turned about hinge{1}_axis, gyro{1}_* did not: "
                         "the gyro1_* and gyro2_* columns are swapped (or plat1_deg and plat2_deg); swap them back",
                         how_many(f), p);
    case HealthCause::kFlipAxis:
      return fmt::format("platform {0} turned about ({1:.2f}, {2:.2f}, {3:.2f}) in its sensor's axes in {4}, where "
                         "hinge{0}_axis in the header gives ({5:.2f}, {6:.2f}, {7:.2f}): the header's hinge axes are "
                         "wrong (a missing hinge{0}_axis line takes the default), or the gyro1_*/gyro2_* columns "
                         "are swapped; fix the header or the columns",
                         p, f.measured_axis[0], f.measured_axis[1], f.measured_axis[2], how_many(f), f.header_axis[0],
                         f.header_axis[1], f.header_axis[2]);
    default:
      return fmt::format("the gyro turned {:.3g}x the change of plat{}_deg about the hinge in {}: neither a unit nor "
                         "a sign explains it; check the angle column's scale, the other platform's angle (a wrong "
                         "resting angle turns the box's rate into the flip: see the findings above) and the gyro's "
                         "range (a gyro that clips in a flip reads it short)",
                         f.value, p, how_many(f));
  }
}

}  // namespace

bool is_flip_cause(HealthCause c) {
  return static_cast<int>(c) >= static_cast<int>(HealthCause::kFlipGyroUnit) &&
         static_cast<int>(c) <= static_cast<int>(HealthCause::kFlipsTooSlow);
}

const char* flip_cause_key(HealthCause c) {
  switch (c) {
    case HealthCause::kFlipGyroUnit: return "flip_gyro_unit";
    case HealthCause::kFlipAngleUnit: return "flip_angle_unit";
    case HealthCause::kFlipTimeUnit: return "flip_time_unit";
    case HealthCause::kFlipNotSeen: return "flip_not_seen";
    case HealthCause::kFlipAngleSign: return "flip_angle_sign";
    case HealthCause::kFlipWrapped: return "flip_wrapped";
    case HealthCause::kFlipSensorsSwapped: return "flip_sensors_swapped";
    case HealthCause::kFlipAxis: return "flip_axis";
    case HealthCause::kFlipTurnRatio: return "flip_turn_ratio";
    case HealthCause::kFlipScale: return "flip_scale";
    case HealthCause::kFlipsUnchecked: return "flips_unchecked";
    case HealthCause::kFlipsTooSlow: return "flips_too_slow";
    default: return "?";
  }
}

std::string describe_flip(const est::HealthFinding& f, const est::EstimatorConfig& cfg) {
  switch (f.cause) {
    case HealthCause::kFlipGyroUnit:
    case HealthCause::kFlipAngleUnit:
    case HealthCause::kFlipTimeUnit: return unit_text(f);
    case HealthCause::kFlipScale: {
      const double err = f.value - 1.0;
      const double wider = std::ceil(std::fabs(err) / 2.0 * 100.0) / 100.0;  // the error at 2 sigma
      const std::string pm = std::isfinite(f.sigma) ? fmt::format(" +- {:.2f}", 100.0 * f.sigma) : std::string();
      return fmt::format("platform {}'s gyro reads each flip as {:.2f}{} % of the angle change ({} of {:g} flips, "
                         "the bias from the rest before each): a scale error of {:+.1f} % along its hinge, {:.1f}x "
                         "scale_misalign_sigma_frac {:g}{}; set scale_misalign_sigma_frac: {:g} (--config) or {}",
                         platform(f), 100.0 * f.value, pm, f.count, f.suggested, 100.0 * err,
                         std::fabs(err) / cfg.scale_misalign_sigma_frac, cfg.scale_misalign_sigma_frac,
                         cfg.self_calibration ? ": the self-calibration's flip gate rejects flips that far off and leaves "
                                                "the scale near its prior"
                                              : " (with --selfcal its flip gate would reject these flips)",
                         wider, calibrate_fix(run_used(cfg, est::GravitySource::kNone)));
    }
    case HealthCause::kFlipsUnchecked:
      if (f.count > 0) {
        return fmt::format("the hinge axes and angle signs were not checked: a gyro clipped in all {} flips so far "
                           "that their turn could not be read (below a fifth of the angle change): a wrong "
                           "hinge*_axis line or angle sign in the header would go unseen, and makes every estimate "
                           "wrong; flip more slowly or record with a larger gyro range (MPU6050: FS_SEL), and check "
                           "hinge1_axis/hinge2_axis and the signs of plat1_deg/plat2_deg by hand",
                           f.count);
      }
      return fmt::format("the hinge axes and angle signs were not checked: in {:g} motion(s) between two rests no "
                         "flip of one platform alone with both angles read was seen (both platforms moved at once, "
                         "or samples were missing in every flip): a wrong hinge*_axis line or angle sign in the "
                         "header would go unseen, and makes every estimate wrong; flip one platform at a time, "
                         "with a rest between flips, and check hinge1_axis/hinge2_axis and the signs of "
                         "plat1_deg/plat2_deg by hand",
                         std::isnan(f.suggested) ? 0.0 : f.suggested);
    case HealthCause::kFlipsTooSlow:
      return fmt::format("{} of {:g} flips took longer than flip_max_s {:g} s (the longest {:.1f} s): the "
                         "self-calibration made no flip update from them, so scale and misalignment stay near "
                         "their prior; set flip_max_s: {:g} (--config)",
                         f.count, f.suggested, cfg.flip_max_s, f.value, std::ceil(f.value + 1.0));
    default: return platform_text(f, cfg);
  }
}

}  // namespace driftless::cli
