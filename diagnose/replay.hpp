// Log-driven kinematics replay: what each gyro should have sensed, rebuilt from a measurement
// log's reference motion (ref_q, ref_p), platform angles and metadata (docs/compare.md).
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "estimator/log.hpp"
#include "estimator/sample.hpp"

namespace driftless::diagnose {

/// How a log is replayed. Units: Hz, deg, deg/s, s.
struct ReplayOptions {
  double resample_hz = kNaN;            // Hz; resample the log to this rate (NaN: replay it at its own rate)
  double default_latitude_deg = 52.0;   // deg; used (and stated) when the log has no latitude_deg
  double flip_rate_threshold_dps = 0.5; // deg/s; a platform turning faster than this is flipping
  double flip_guard_s = 0.05;           // s; samples this close to a flip count as flipping
  double static_rate_limit_dps = 0.5;   // deg/s; without ref_q, larger gyro swings mean "moving"
  double replay_error_limit_dps = 0.01; // deg/s; a kink of the rate whose spike in the second
                                        // difference of the interval mean rates exceeds this ...
  double kink_ratio = 8.0;              // ... and this many times its +-0.5 s neighbourhood's mean
                                        // is left out (the rate cannot be rebuilt there)
  double rough_guard_s = 0.03;          // s; samples this close to such a kink (plus the FIR's
                                        // half length) are left out too
  /// Throws std::invalid_argument naming the field on a bad value.
  void validate() const;
};

/// Per-sample truth rebuilt from a log, plus what was measured. Sensor index s = 0, 1.
struct Replay {
  std::size_t size() const { return t_s.size(); }
  /// d(w_radps)/dt of sensor s, axis j, at sample k by the maximally flat central
  /// differentiator over 2 x 4 neighbours (central differences near the ends and where a
  /// neighbour is not finite, 0 where unknown), rad/s^2, sensor axes: computed when asked (a
  /// stored copy was 17 MB an hour), one axis at a time (what a channel's column needs)
  double dw_axis_radps2(int s, std::size_t k, int j) const;
  /// Neighbours on each side that dw_axis_radps2's stencil reads, samples.
  static constexpr std::size_t kAngularAccelHalfWidth = 4;

  std::vector<double> t_s;                               // s, log time
  std::array<std::vector<Eigen::Vector3d>, 2> gyro_dps;  // measured, sensor axes, deg/s
  std::array<std::vector<Eigen::Vector3d>, 2> w_radps;   // ideal inertial rate y_i, sensor axes
  // the slowly varying or small series below are stored as float (7 significant digits: 1e-6
  // m/s^2 of a specific force, 1e-12 rad/s of the latitude sensitivity), half the memory of double
  std::array<std::vector<Eigen::Vector3f>, 2> f_mps2;    // specific force, sensor axes
  // d(w_body)/d(latitude) per rad of latitude: the Earth-rate part's sensitivity, box axes (a
  // sensor's is R_i^T of it: sensor_from_box; one box series instead of one per sensor)
  std::vector<Eigen::Vector3f> dw_dlat_box_radps;
  // the Earth-rate part of w_body, box axes, rad/s: kept only where the latitude is assumed (the
  // log states none: whether its reference frame turns with the Earth is then unknown too)
  std::vector<Eigen::Vector3f> earth_box_radps;
  // box inertial rate, box axes, as float (the regimes and correlations use it; the sensors'
  // rates w_radps were formed from the double)
  std::vector<Eigen::Vector3f> w_body_radps;
  /// R_i^T: box axes to sensor s's axes at sample k (the platform at its logged angle); NaN
  /// where the angle is unknown.
  Eigen::Matrix3d sensor_from_box(int s, std::size_t k) const;
  std::vector<Eigen::Vector3f> f_body_mps2;              // box specific force, box axes
  // as float (7 digits: 1e-5 deg of an angle, 4e-6 degC of a temperature; the sensors' series
  // were made from the logged doubles)
  std::array<std::vector<float>, 2> plat_deg;            // as logged; NaN when unknown
  std::array<std::vector<float>, 2> temp_c;              // logged die temperature, NaN if absent
  std::vector<std::uint8_t> usable;    // gyro finite and the truth is known
  std::vector<std::uint8_t> flipping;  // a platform moves, or its angle is unknown
  std::vector<std::uint8_t> rough;     // the rate cannot be rebuilt from ref_q here (a kink)
  std::array<std::vector<float>, 2> since_flip_s;       // s since platform i last stopped (inf)
  std::array<std::vector<std::int8_t>, 2> last_flip_dir; // +1/-1: direction of that flip, 0 none
  std::array<std::vector<std::int8_t>, 2> rest_side;     // +1/-1 platform at rest on that side, 0

  std::array<Eigen::Vector3d, 2> hinge_axis{Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitX()};
  double latitude_deg = kNaN;
  bool latitude_assumed = false;  // the log states no latitude_deg (default_latitude_deg is used)
  double sample_rate_hz = kNaN;   // Hz, of the replayed series (after any resampling)
  double log_rate_hz = kNaN;      // Hz, as found in the log
  bool resampled = false;
  bool encoder_readback = false;  // metadata platform_readback: encoder (angles are true angles)
  bool has_ref_q = false, has_ref_p = false, has_accel = false, has_temp = false;
  // 1: the single-sensor form (one IMU on a rigid body against ref_q; docs/log-format.md):
  // sensor 2's series are NaN and its channels take no part in the fits
  int sensors = 2;
  log::Metadata meta;
  std::string log_path;
  std::size_t rows_missing_gyro = 0;
  std::vector<std::string> notes;  // assumptions and conversions, said in the report
};

/// Replays a log file, the single-sensor form included (it needs ref_q). Throws
/// std::runtime_error with an actionable message when the log cannot be replayed (moving box
/// without ref_q, a single-sensor log without ref_q, a ref_q that is not a rotation, ...).
Replay replay_log(const std::filesystem::path& path, const ReplayOptions& opt);

/// Replays samples already in memory (tests, bridges); `where` names the source in messages.
Replay replay_samples(const std::vector<Sample>& samples, const log::Metadata& meta,
                      std::uint32_t fields, const ReplayOptions& opt, const std::string& where);

}  // namespace driftless::diagnose
