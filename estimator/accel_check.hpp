// The accelerometer side of the self-calibration (docs/estimator.md sections 1b and 6.1): which
// source drives the g-sensitivity states (the log's accel columns, gravity from ref_q, none), the
// gravity that ref_q implies in each sensor's axes, and the check of the accel columns at the
// standstills (their median |f| against 1 g: a column in g or mg, or an empty one). Eigen + std only.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Geometry>

#include "estimator/config.hpp"
#include "estimator/filter.hpp"
#include "estimator/gravity_source.hpp"
#include "estimator/health.hpp"
#include "estimator/sample.hpp"

namespace driftless::est {

/// The source for a log with the column groups `fields` (SampleField bits): accel, else ref_q, else none.
GravitySource gravity_source(std::uint32_t fields);

/// Sets s.accel1_mps2 / s.accel2_mps2 to gravity's specific force from ref_q, M_i^T C^T (0, 0, g)
/// (C = ref_q as q_enu_from_body, M_i = filter.body_from_sensor at the platform angle read), for
/// each sensor whose platform angle is known; NaN otherwise and when ref_q is not finite.
void gravity_from_ref_q(const DriftlessFilter& filter, Sample& s);

/// The warning of a pass whose G states took gravity from ref_q: the bound on the box's own
/// acceleration that went into R (EstimatorConfig::ref_gravity_accel_sigma_g, ref_gravity_speed_mps).
std::string gravity_from_ref_q_note(double accel_sigma_g, double speed_mps);

/// What a sensor's accel columns read at the standstills, against gravity.
enum class AccelReading : std::uint8_t {
  kNotChecked,  // no standstill sample with accel values
  kOk,          // median |f| within kAccelUnitTolerance of g (m/s^2)
  kOtherUnit,   // median |f| within the tolerance of g in another unit of the unit table (g, mg, ug)
  kEmpty,       // median |f| below kAccelEmptyFraction g (all zero, or not filled)
  kOff,         // none of these: a wrong scale, or a box far from 1 g
};
inline constexpr double kAccelUnitTolerance = 0.1;   // relative
inline constexpr double kAccelEmptyFraction = 0.01;  // of g

/// One sensor's result.
struct AccelSensorReading {
  AccelReading reading = AccelReading::kNotChecked;
  double median_norm = kNaN;     // median |f| of the standstill samples, in the column's numbers
  std::uint64_t samples = 0;     // standstill samples with finite accel values
  std::string_view unit_suffix;  // kOtherUnit: the unit-table suffix that fits ("g", "mg", ...)
  double factor = kNaN;          // kOtherUnit: multiply the column by this to get m/s^2
};
using AccelCheckResult = std::array<AccelSensorReading, 2>;

/// Classifies the median |f| `median_norm` (the column's numbers) of `samples` standstill samples against g.
AccelSensorReading classify_accel(double median_norm, std::uint64_t samples);

/// Collects |f| of each sensor over the samples where both platforms rest (a log-binned
/// histogram: the median to 0.6 %, constant memory on a 14 h log).
class AccelCheck {
 public:
  void push(const Sample& s, bool at_rest);
  AccelCheckResult finish() const;

 private:
  static constexpr int kBinsPerDecade = 400;          // 0.58 % per bin
  static constexpr double kLowestLog10 = -6.0;        // |f| below 1e-6 counts as zero
  static constexpr int kBins = 12 * kBinsPerDecade;  // up to 1e6
  std::array<std::array<std::uint32_t, kBins>, 2> bins_{};
  std::array<std::uint64_t, 2> zeros_{}, n_{};
};

/// The accel findings (kAccelUnit, kAccelEmpty) of `r`, ahead of the others (they are their cause):
/// `failed` under self-calibration (its G states are driven by these columns), else `degraded`
/// (the --calib G correction, the up direction of --box-at-rest); a median |f| that fits no unit
/// is `degraded` under self-calibration, a note otherwise.
void add_accel_findings(HealthReport& h, const AccelCheckResult& r, bool self_calibration);

/// --calib without self-calibration applies G and E as exact corrections. An element whose sigma
/// is above a third of its size and above its floor (kCalibGSigmaFloorDpsPerG deg/s per g: that
/// much rate at 1 g; kCalibESigmaFloor: 0.1 deg/s at 50 deg/s) is not known well enough for that
/// (a self-calibration leaves the elements its log did not observe at their prior).
inline constexpr double kCalibGSigmaFloorDpsPerG = 0.005;
inline constexpr double kCalibESigmaFloor = 0.002;
/// One such element: sensor 1 or 2, G (else E), row, column, its value and sigma.
struct UncertainElement {
  int sensor = 1;
  bool g = true;
  int row = 0, col = 0;
  double value = kNaN, sigma = kNaN;
};
/// The uncertain elements of `cal`'s G (with G_sigma) and E (with E_sigma).
std::vector<UncertainElement> uncertain_calibration(const Calibration& cal);
/// A degraded `calib_uncertain` finding ahead of the others when `cal` holds uncertain elements
/// (components: sensor * 100 + (g ? 0 : 10) + 3 row + col each; positions_deg: {value, sigma} each;
/// count: how many; value: the G and E elements with a sigma).
void add_calib_finding(HealthReport& h, const Calibration& cal);

}  // namespace driftless::est
