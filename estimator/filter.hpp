// The DriftLess bias filter (paper section 2): a streaming Kalman filter on the state [b1; b2]
// (deg/s) fed one Sample at a time. The same object runs on a log, on a replay and live in the
// HIL bridge; it survives a source switch (on_source_switch()). Eigen + std only.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <deque>
#include <iosfwd>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "estimator/box_geometry.hpp"
#include "estimator/config.hpp"
#include "estimator/flip_update.hpp"
#include "estimator/sample.hpp"
#include "estimator/standstill.hpp"

namespace driftless::est {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

/// A named slice of the state vector (like PX4's State::gyro_bias.idx).
struct StateSlice {
  Eigen::Index start;
  Eigen::Index size;
};
inline constexpr StateSlice kBias1{0, 3};  // b1, deg/s, sensor-1 axes
inline constexpr StateSlice kBias2{3, 3};  // b2, deg/s, sensor-2 axes
inline constexpr int kStateDim = 6;        // the bias [b1; b2]
// the bias temperature coefficients k_i, deg/s per degC, sensor-i axes: b_i moves by k_i dT_i
// when sensor i's temperature changes (docs/estimator.md section 1a); frozen at their prior
// while no temperature is known or temp_coef_sigma_dps_per_degc is 0
inline constexpr StateSlice kTempCoef1{6, 3};
inline constexpr StateSlice kTempCoef2{9, 3};
// self-calibrating mode: each sensor's g-sensitivity G_i (deg/s per g, sensor axes, row-major:
// G_i[r][c] at start + 3 r + c): y_i += G_i f_i, f_i the specific force in g from the accel
// columns (docs/estimator.md section 1b); frozen at 0 (P = 0) unless self_calibration is on
inline constexpr StateSlice kGSens1{12, 9};
inline constexpr StateSlice kGSens2{21, 9};
// self-calibrating mode: each sensor's scale-factor and misalignment error E_i (dimensionless,
// sensor axes, row-major like G_i): y_i = (I + E_i) w_i + b_i + ..., w_i the true rate in sensor-i
// axes; driven by the fused body rate averaged over each standstill (docs/estimator.md section
// 1c); frozen at 0 (P = 0) unless self_calibration is on and scale_misalign_sigma_frac > 0
inline constexpr StateSlice kScale1{30, 9};
inline constexpr StateSlice kScale2{39, 9};
// self-calibrating mode with scale states: each platform's rest angle errors at its two end stops
// (deg, about its hinge; [platform 1 at -, at +, platform 2 at -, at +], by the sign of the angle
// read): a stop off by d turns that sensor's reading of the box rate by d (standstills) and makes
// each flip d_end - d_start larger than the readings say (docs/estimator.md section 1g); prior
// sigma flip_angle_sigma_deg, frozen at 0 unless has_stop_states()
inline constexpr StateSlice kStopAngle{48, 4};
inline constexpr int kFullStateDim = 52;
using StateVector = Eigen::Matrix<double, kFullStateDim, 1>;
using StateMatrix = Eigen::Matrix<double, kFullStateDim, kFullStateDim>;

/// What push() did with a sample. It never throws per sample.
enum class PushStatus {
  kInvalid,       // NaN/missing gyro value or time: the sample did not enter the state
  kTimeNotIncreasing,  // t <= previous t: dropped (call on_source_switch() for a new timeline)
  kMoving,        // a platform is moving (or its angle unknown): no residual
  kSettling,      // both at rest, inside the settle margin
  kAccumulating,  // added to the current standstill
  kUpdated,       // a standstill (or sample) update was accepted
  kRejected,      // an update was rejected by the NIS gate (reported in last_update())
};
const char* to_string(PushStatus s);

/// One measurement update.
struct UpdateRecord {
  std::uint64_t index = 0;    // 0-based count of updates (accepted and rejected)
  double t_s = kNaN;          // s, time of the update (last sample of the standstill)
  double t_start_s = kNaN;    // s, first sample used
  std::size_t samples = 0;    // samples averaged into the residual
  double plat1_deg = kNaN;    // deg, positions used for H
  double plat2_deg = kNaN;
  int dim = 0;                // residual dimension: 3, or 6 (paper stacking)
  Vector6d bias_dps = Vector6d::Zero();   // estimate after the update
  Vector6d sigma_dps = Vector6d::Zero();  // sqrt(diag P) after the update
  Vector6d innovation_dps = Vector6d::Zero();  // r - H x (first `dim` entries)
  double nis = kNaN;          // innovation^T S^-1 innovation
  double nis_gate = kNaN;     // chi-square gate at nis_gate_probability and `dim`
  bool accepted = false;
  bool relocked = false;      // taken after gate_relock_after rejections in a row, P widened
  double relock_nis = kNaN;   // a re-lock: the NIS that triggered it (nis is the one after widening)
  bool at_end = false;        // the stream ended inside this standstill (finish())
};

/// Outputs for the sample last pushed.
struct SampleOutput {
  double t_s = kNaN;
  Eigen::Vector3d y1c_dps = Eigen::Vector3d::Constant(kNaN);  // y1 - b1_hat, sensor-1 axes
  Eigen::Vector3d y2c_dps = Eigen::Vector3d::Constant(kNaN);  // y2 - b2_hat, sensor-2 axes
  // fused inertial body rate in box axes (Earth rate included): the mean of M_i y_ic over the
  // sensors whose platform is at rest with a known angle; NaN when none is
  Eigen::Vector3d rate_body_dps = Eigen::Vector3d::Constant(kNaN);
  Eigen::Vector3d rate_body_raw_dps = Eigen::Vector3d::Constant(kNaN);  // the same, uncorrected
  // the same, corrected by the fixed bias of set_fixed_bias_dps() (the uncorrected rate until set)
  Eigen::Vector3d rate_body_fixed_dps = Eigen::Vector3d::Constant(kNaN);
  int sensors_fused = 0;  // 0, 1 or 2
  // platform positions in force (deg; NaN = unknown) and whether both platforms are at rest, i.e.
  // the residual of eq. (2) is valid for this sample (fault detection watches it)
  double plat1_deg = kNaN, plat2_deg = kNaN;
  bool at_rest = false;
  // standstill: gyro: both platforms move, no sensor reads the box rate alone (rate_body NaN)
  bool both_moving = false;
  PushStatus status = PushStatus::kInvalid;
};

/// Counters since construction.
struct FilterCounters {
  std::uint64_t samples = 0;
  std::uint64_t invalid = 0;
  std::uint64_t time_not_increasing = 0;
  std::uint64_t updates = 0;
  std::uint64_t rejected = 0;
  std::uint64_t standstills_too_short = 0;
  std::uint64_t simultaneous_flips = 0;  // standstill: gyro: flips of both platforms at once
  std::uint64_t schedule_mismatches = 0;  // paper mode: measured positions differ from eq. (5)
  // paper mode: standstills with both angles read, and those where a platform rested more than
  // calibration.match_tolerance_deg from +-flip_angle_deg (the angles eq. (5) builds H from); the first
  // such rest angle (deg, as read) for the health text
  std::uint64_t paper_standstills = 0;
  std::uint64_t rest_angle_mismatches = 0;
  double rest_angle_mismatch_deg = kNaN;
  std::uint64_t source_switches = 0;
  std::uint64_t relocks = 0;  // gate re-locks after gate_relock_after consecutive rejections
  // box-dwell updates of the vertical rate (box_dwell_updates; not in `updates`/`rejected`)
  std::uint64_t box_dwell_updates = 0;
  std::uint64_t box_dwell_rejected = 0;
  // quiet stretches not used as box dwells because the box rate trended through them (a rocking or
  // swinging box passing a turning point): box_dwell_trend() (not in box_dwell_updates)
  std::uint64_t box_dwell_moving = 0;
  // quiet stretches not used as box dwells because ref_q turned through them: the box's mean rate
  // over the dwell's samples (ref_q's slope) above the dwell row's sigma (not in box_dwell_updates)
  std::uint64_t box_dwell_turned = 0;
  // flip updates of the scale/misalignment (flip_updates; not in `updates`/`rejected`)
  std::uint64_t flip_updates = 0;
  std::uint64_t flip_rejected = 0;
  double flip_nis_sum = 0.0;  // sum of the accepted flip updates' NIS (3 dof each)
  std::uint64_t flip_clipped = 0;  // flips skipped because a gyro clipped in them (flip_clipped())
};

/// What an accepted update changed (for an offline smoother: estimator/smoother.hpp). The pointers
/// are valid during the call only.
struct UpdateSnapshot {
  double t_s = kNaN;                             // s, the time x and P refer to
  std::array<double, 2> temp_ref_c{kNaN, kNaN};  // degC, the temperatures the bias refers to
  const StateVector* x_prior = nullptr;          // before the gain (predicted; a re-lock's widening in)
  const StateMatrix* P_prior = nullptr;
  const StateVector* x_post = nullptr;           // after it
  const StateMatrix* P_post = nullptr;
};

/// Told of every accepted update (set_update_observer).
class UpdateObserver {
 public:
  virtual ~UpdateObserver() = default;
  virtual void on_accepted_update(const UpdateSnapshot& u) = 0;
};

/// The streaming DriftLess filter.
class DriftlessFilter {
 public:
  /// Builds the filter for the box `box` (hinge axes, sample rate, latitude, flip angle; from a
  /// log with box_geometry_from_metadata()). Throws std::invalid_argument on a bad config or box.
  DriftlessFilter(const EstimatorConfig& cfg, const BoxGeometry& box);

  /// Feeds one sample; returns what happened. Never throws; NaN samples never touch the state.
  PushStatus push(const Sample& s);
  /// The stream ended: a standstill in progress (the log ends at rest, or never moved) is used
  /// with all its samples. Returns kUpdated / kRejected when it made an update, else kMoving.
  PushStatus finish();
  /// A new source takes over (HIL switch-over, a gap): the standstill in progress is dropped and
  /// paper-mode stacking restarts; the estimate and P are kept. `box` (optional) may change the
  /// hinge axes and sample rate; time may restart.
  void on_source_switch(const BoxGeometry* box = nullptr);

  /// A bias [b1; b2] (deg/s) held fixed for the comparison output rate_body_fixed_dps: what a box
  /// whose gyros were calibrated once and never again would use. Zero until set; the filter's
  /// own state is not touched.
  void set_fixed_bias_dps(const Vector6d& b) { fixed_bias_ = b; }
  /// Every accepted update is handed to `o` (nullptr: none); for the offline smoother.
  void set_update_observer(UpdateObserver* o) { observer_ = o; }
  /// The corrected outputs of the following push() calls use state `x` (bias referred to
  /// `temp_ref_c`) instead of the filter's own (nullptr: its own); both must outlive those calls.
  /// The filter itself still updates as always (--smooth's second pass).
  void set_output_state(const StateVector* x, const std::array<double, 2>* temp_ref_c) {
    output_x_ = x;
    output_temp_ref_ = temp_ref_c;
  }

  /// Bias estimate [b1; b2], deg/s (b_i in sensor-i axes), at the temperatures of the last
  /// update (temperature_ref_c()).
  Vector6d bias_dps() const { return x_.head<kStateDim>(); }
  Eigen::Vector3d bias1_dps() const { return x_.segment<3>(kBias1.start); }
  Eigen::Vector3d bias2_dps() const { return x_.segment<3>(kBias2.start); }
  /// Its covariance, (deg/s)^2.
  Matrix6d covariance_dps2() const { return P_.topLeftCorner<kStateDim, kStateDim>(); }
  Vector6d sigma_dps() const { return covariance_dps2().diagonal().cwiseSqrt(); }
  /// Temperature coefficients [k1; k2], deg/s per degC, their sigma, and whether they are states.
  Vector6d temp_coef_dps_per_degc() const { return x_.segment<6>(kTempCoef1.start); }
  Vector6d temp_coef_sigma_dps_per_degc() const { return P_.diagonal().segment<6>(kTempCoef1.start).cwiseSqrt(); }
  bool has_temp_states() const { return cfg_.temp_coef_sigma_dps_per_degc > 0.0; }
  /// g-sensitivity G_i of sensor 1 or 2 (deg/s per g) and the sigma of each element.
  Eigen::Matrix3d g_sensitivity_dps_per_g(int sensor) const;
  Eigen::Matrix3d g_sensitivity_sigma_dps_per_g(int sensor) const;
  bool has_gsens_states() const { return cfg_.self_calibration && cfg_.gsens_sigma_dps_per_g > 0.0; }
  /// scale-factor and misalignment error E_i of sensor 1 or 2 (fraction) and each element's sigma.
  Eigen::Matrix3d scale_misalign(int sensor) const;
  Eigen::Matrix3d scale_misalign_sigma(int sensor) const;
  bool has_scale_states() const { return cfg_.self_calibration && cfg_.scale_misalign_sigma_frac > 0.0; }
  /// Box dwells measure the vertical rate (self-calibrating mode, box_dwell_updates, and not
  /// box_at_rest, whose standstill rows measure the same already)
  bool uses_box_dwells() const { return cfg_.self_calibration && cfg_.box_dwell_updates && !cfg_.box_at_rest; }
  /// Each flip of one platform measures the moving sensor's scale/misalignment (flip_updates,
  /// self-calibrating mode with scale states; docs/estimator.md section 1f)
  bool uses_flips() const { return has_scale_states() && cfg_.flip_updates; }
  /// End-stop angle states (kStopAngle): general mode, a rest-angle sigma (flip_angle_sigma_deg
  /// > 0) and no calibrated matrices (which hold the true angles)
  bool has_stop_states() const {
    return cfg_.mode == FilterMode::kGeneral && cfg_.flip_angle_sigma_deg > 0.0 && cfg_.calibration.empty();
  }
  /// The rest-angle errors [platform 1 at -, at +; platform 2 at -, at +] (deg) and their sigma.
  Eigen::Vector4d stop_angle_deg() const { return x_.segment<4>(kStopAngle.start); }
  Eigen::Vector4d stop_angle_sigma_deg() const { return P_.diagonal().segment<4>(kStopAngle.start).cwiseSqrt(); }
  /// Index in the state of platform `platform`'s end stop at the angle read `plat_deg`.
  static Eigen::Index stop_index(int platform, double plat_deg) {
    return kStopAngle.start + 2 * (platform - 1) + (plat_deg < 0.0 ? 0 : 1);
  }
  /// Sigma of the correction the filter applies, o_i = b_i + G_i f_i at the specific force of
  /// the last update (deg/s): what "locked" means. The bias sigma without self-calibration; with
  /// it, b_i alone may stay unobservable (a g-sensitivity along a fixed gravity looks like bias).
  Vector6d correction_sigma_dps() const;
  /// The specific force of the last update in sensor `sensor`'s axes (g; NaN before one with accel).
  const Eigen::Vector3d& last_specific_force_g(int sensor) const { return last_f_g_[sensor == 1 ? 0 : 1]; }
  /// The whole state [b1; b2; k1; k2; G1; G2; E1; E2] and its covariance (units as above).
  const StateVector& state() const { return x_; }
  const StateMatrix& full_covariance() const { return P_; }
  /// Temperatures (degC) the bias estimate refers to; NaN until the first one is known.
  const std::array<double, 2>& temperature_ref_c() const { return temp_ref_c_; }
  /// The latest update (has_update() false before the first).
  const UpdateRecord& last_update() const { return last_update_; }
  bool has_update() const { return counters_.updates > 0; }
  /// The bias covariance (deg/s)^2 carried to time `t_s` by the random walk (P refers to the last
  /// update's time; the bias wanders on between updates): what a per-sample error is checked against.
  Matrix6d covariance_dps2_at(double t_s) const {
    Matrix6d P = covariance_dps2();
    if (std::isfinite(t_filter_s_) && t_s > t_filter_s_) P.diagonal().array() += q_rate_dps2_per_s_ * (t_s - t_filter_s_);
    return P;
  }
  /// Corrected outputs and fused body rate of the sample last pushed.
  const SampleOutput& output() const { return out_; }
  const FilterCounters& counters() const { return counters_; }
  /// The standstill detector (its gyro flip tracker, the angle columns' jitter).
  const StandstillDetector& standstill() const { return standstill_; }
  const EstimatorConfig& config() const { return cfg_; }
  const BoxGeometry& geometry() const { return box_; }

  /// M_body_from_sensor for sensor 1 or 2 at platform angle `plat_deg` (Rot(a_i, angle) or the
  /// calibrated matrix). For tests and diagnosis.
  Eigen::Matrix3d body_from_sensor(int sensor, double plat_deg) const;

 private:
  // one standstill's residual of eq. (2), its rows of H and its noise
  struct Residual3 {
    bool valid = false;
    Eigen::Vector3d r = Eigen::Vector3d::Zero();
    Eigen::Matrix<double, 3, kFullStateDim> H = Eigen::Matrix<double, 3, kFullStateDim>::Zero();
    Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
    int pattern = 0;  // position index 0..3 of eq. (5)'s sequence
  };
  void use_calibration_prior();
  PushStatus push_corrected(const Sample& s);
  int use_segment(const StandstillSegment& seg);
  void residual_rows(const StandstillSegment& seg, const Eigen::Matrix3d& M1, const Eigen::Matrix3d& M2,
                     double rate_hz, Residual3& out);
  bool rest_row(const StandstillSegment& seg, const Eigen::Matrix3d& M1, const Eigen::Matrix3d& M2,
                double var_dps2, Eigen::Matrix<double, 1, kFullStateDim>& h, double& z, double& var_z) const;
  void predict_to(double t_s);
  void predict_temperature(double temp1_c, double temp2_c);
  Vector6d bias_at(const Sample& s, const StateVector& x, const std::array<double, 2>& temp_ref) const;
  // the random walk over an averaging window, the update made at or after its end (docs/estimator.md
  // section 1h): the window mean is b(t) - u; Cov(u, J) = q c_s and Var(u) = q v_s, J the walk the
  // prior's error holds; zero for a point measurement (flips, paper mode)
  struct WindowWander {
    double c_s = 0.0;
    double v_s = 0.0;
  };
  static WindowWander window_wander(double t_first_s, double t_last_s, double t_update_s);
  // one update of D rows (D = 1, 3, 4 or 6: r is D x 1, H D x kFullStateDim, R D x D). One function
  // for every D: a template over D compiled the 52-state products once per D, two thirds of GCC's
  // compile time of filter.cpp (56 s against 22 s at -O2); the updates come once per standstill.
  // The default spelled out, not '= {}': clang refuses a default argument that needs the nested
  // struct's member initializers while DriftlessFilter is still incomplete (GCC accepts it)
  using Rows = Eigen::Ref<const Eigen::MatrixXd>;
  bool update(const Rows& r, const Rows& H, const Rows& R, UpdateRecord& rec, bool may_relock = true,
              WindowWander wander = WindowWander{0.0, 0.0});
  void emit_update(const UpdateRecord& rec, bool accepted);
  void check_paper_position(double plat1_deg, double plat2_deg, int pattern);
  void fuse_rate(const Sample& s, const StandstillStep& st);
  Eigen::Vector3d box_rate_dps(const StandstillSegment& s, const Eigen::Matrix3d& M1, const Eigen::Matrix3d& M2) const;
  Eigen::Matrix3d unknown_accel_cov_dps2(const Eigen::Matrix3d& M1, const Eigen::Matrix3d& M2, double s2,
                                         const Eigen::Vector3d& w_box_dps) const;
  void stop_rows(const StandstillSegment& s, const Eigen::Matrix3d& M1, const Eigen::Matrix3d& M2, Residual3& cur) const;
  void add_rest_angle_noise(const StandstillSegment& seg, const Eigen::Matrix3d& M1, const Eigen::Matrix3d& M2,
                            Eigen::Matrix3d& R) const;
  void scale_rows(const StandstillSegment& seg, const Eigen::Matrix3d& M1, const Eigen::Matrix3d& M2,
                  Residual3& out);
  void skip_paper_step();
  // box dwells (cfg_.box_dwell_updates, docs/estimator.md section 1d)
  bool box_quiet(const Sample& s) const;
  void track_box_dwell(const Sample& s);
  void close_box_dwell(double temp1_c, double temp2_c);
  void add_dwell_piece(const StandstillSegment& one, const Eigen::Vector4d& ref_q_wxyz);
  void use_box_dwell();
  bool unturned_dwell(const Eigen::Matrix3d& M1, const Eigen::Matrix3d& M2, StandstillSegment& seg, double& turn_dps) const;
  // flip updates (cfg_.flip_updates, docs/estimator.md section 1f)
  SensorErrors errors_of(int sensor) const;
  void use_flip();

  EstimatorConfig cfg_;
  BoxGeometry box_;
  double q_rate_dps2_per_s_ = 0.0;
  // --calib terms without states of their own: fixed corrections (use_calibration_prior)
  bool fixed_g_ = false, fixed_e_ = false, fixed_stops_ = false;
  UpdateObserver* observer_ = nullptr;
  const StateVector* output_x_ = nullptr;
  const std::array<double, 2>* output_temp_ref_ = nullptr;
  std::array<Eigen::Matrix3d, 2> fixed_E_inv_{Eigen::Matrix3d::Identity(), Eigen::Matrix3d::Identity()};

  StateVector x_ = StateVector::Zero();
  Vector6d fixed_bias_ = Vector6d::Zero();  // deg/s, for rate_body_fixed_dps only
  StateMatrix P_ = StateMatrix::Identity();
  // specific force (g, sensor axes) of the last update that had accel columns, per sensor
  std::array<Eigen::Vector3d, 2> last_f_g_{Eigen::Vector3d::Constant(kNaN), Eigen::Vector3d::Constant(kNaN)};
  // mean true rate (deg/s, sensor axes) of the last standstill, per sensor (scale states)
  std::array<Eigen::Vector3d, 2> last_w_dps_{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  std::array<double, 2> temp_ref_c_{kNaN, kNaN};  // degC, temperatures x_'s bias refers to
  int consecutive_rejections_ = 0;
  double t_filter_s_ = kNaN;  // time P and x refer to
  double last_t_s_ = kNaN;

  StandstillDetector standstill_;
  FlipWindow flips_;
  // the box dwell in progress: samples older than box_dwell_margin_s in dwell_, the newer ones
  // (dropped if the dwell ends now) in dwell_recent_; armed once the correction is known
  struct DwellSample {
    double t_s;
    Eigen::Vector3d gyro1_dps, gyro2_dps, accel1_mps2, accel2_mps2;
    double temp1_c, temp2_c;
    Eigen::Vector3d rate_dps;  // the corrected fused body rate
    Eigen::Vector4d ref_q_wxyz;  // the sample's ref_q (NaN: none)
  };
  // least-squares line of the fused rate against time over a dwell (t from its first sample)
  struct DwellTrend {
    double n = 0.0, st = 0.0, stt = 0.0;
    Eigen::Vector3d sw = Eigen::Vector3d::Zero(), stw = Eigen::Vector3d::Zero(), sww = Eigen::Vector3d::Zero();
    void add(double t_s, const Eigen::Vector3d& w);
    // sum over the axes of (slope / its standard error)^2, the error from the scatter about the line
    double chi2() const;
    // deg/s, the line's largest change over the dwell on one axis (|slope| times the span)
    double change_dps() const;
  };
  StandstillSegment dwell_;
  DwellTrend dwell_trend_;
  std::deque<DwellSample> dwell_recent_;
  // the dwell in pieces of kDwellPieceS (filter.cpp), each with ref_q at its first and last sample
  // that has it (t0_s NaN: none): the turn between two pieces' ref_q over that span is the box's mean
  // rate there (docs/estimator.md section 1d). The first and last kDwellEdgePieces stay apart (the
  // end or start of a move ref_q sees there is dropped), the ones between are merged into one
  struct DwellPiece {
    StandstillSegment seg;
    double t0_s = kNaN, t1_s = kNaN;
    Eigen::Quaterniond q0 = Eigen::Quaterniond::Identity(), q1 = Eigen::Quaterniond::Identity();
    void add(const DwellPiece& later);
  };
  std::vector<DwellPiece> dwell_pieces_;
  double dwell_quiet_since_s_ = kNaN;
  bool dwell_armed_ = false;
  double gate1_ = 0.0, gate3_ = 0.0, gate4_ = 0.0, gate6_ = 0.0;
  // cached M_body_from_sensor of the last angle asked for, per sensor
  mutable std::array<double, 2> cache_deg_{kNaN, kNaN};
  mutable std::array<Eigen::Matrix3d, 2> cache_M_{Eigen::Matrix3d::Identity(), Eigen::Matrix3d::Identity()};

  // paper mode: the previous standstill (for the 6-dim stack) and the eq. (5) counter
  Residual3 prev_res_;
  std::int64_t paper_k_ = -1;   // k of eq. (5); -1 until the phase is known

  UpdateRecord last_update_;
  SampleOutput out_;
  FilterCounters counters_;
};

}  // namespace driftless::est
