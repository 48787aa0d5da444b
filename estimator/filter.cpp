#include "estimator/filter.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <utility>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <Eigen/LU>

#include "estimator/geometry.hpp"
#include "estimator/stats.hpp"
#include "estimator/standstill.hpp"

namespace driftless::est {
namespace {

// a quiet stretch whose fused rate trends both significantly (sum over the axes of the slope's t^2,
// chi-square with 3 dof for a box at rest and white noise: 99.99 % is 21.1, the margin covers noise
// a low-pass filter made correlated) and by more than a bias can move in a dwell (the line's change
// over it) is a box passing a turning point (rocking, swinging), not at rest. Measured changes: at
// rest 0.001-0.031 deg/s (the twin's static and Fig. 9 dwells, slow bias wander and temperature),
// a box rocking 20 deg over 17 s 2.8 deg/s
constexpr double kDwellTrendChi2 = 50.0;
constexpr double kDwellTrendChangeDps = 0.25;
// a dwell is kept in pieces of this length, of which up to kDwellEdgePieces at each end may be
// dropped where ref_q turned in them (the end of the move before, the start of the one after: a
// car's turn slows to below the 2 deg/s quiet limit over its last 0.5 s)
constexpr double kDwellPieceS = 0.5;
constexpr int kDwellEdgePieces = 4;

bool finite(double v) { return std::isfinite(v); }

// a sample's ref_q (q_enu_from_body, w x y z), normalised; false when it has none
bool ref_q_of(const Eigen::Vector4d& wxyz, Eigen::Quaterniond& q) {
  if (!wxyz.allFinite() || !(wxyz.norm() > 0.0)) return false;
  q = Eigen::Quaterniond(wxyz[0], wxyz[1], wxyz[2], wxyz[3]).normalized();
  return true;
}

// `b`'s samples added to `a` (b follows a in time)
void add_segment(StandstillSegment& a, const StandstillSegment& b) {
  if (b.n == 0) return;
  if (a.n == 0) a.t_first_s = b.t_first_s;
  a.t_last_s = b.t_last_s;
  a.n += b.n;
  a.n_accel += b.n_accel;
  a.sum_gyro1_dps += b.sum_gyro1_dps;
  a.sum_gyro2_dps += b.sum_gyro2_dps;
  a.sum_accel1_mps2 += b.sum_accel1_mps2;
  a.sum_accel2_mps2 += b.sum_accel2_mps2;
  a.n_temp += b.n_temp;
  a.sum_temp1_c += b.sum_temp1_c;
  a.sum_temp2_c += b.sum_temp2_c;
}

// the rotation (deg, in the axes of `from`) that turns `from` into `to`
Eigen::Vector3d rotation_deg(const Eigen::Quaterniond& from, const Eigen::Quaterniond& to) {
  Eigen::Quaterniond d = from.conjugate() * to;
  if (d.w() < 0.0) d.coeffs() *= -1.0;
  const Eigen::AngleAxisd aa(d);
  return aa.axis() * (aa.angle() * kDegPerRad);
}

}  // namespace

const char* to_string(PushStatus s) {
  switch (s) {
    case PushStatus::kInvalid: return "invalid";
    case PushStatus::kTimeNotIncreasing: return "time_not_increasing";
    case PushStatus::kMoving: return "moving";
    case PushStatus::kSettling: return "settling";
    case PushStatus::kAccumulating: return "accumulating";
    case PushStatus::kUpdated: return "updated";
    case PushStatus::kRejected: return "rejected";
  }
  return "?";
}

// ---------------------------------------------------------------------------------------------
// the filter

DriftlessFilter::DriftlessFilter(const EstimatorConfig& cfg, const BoxGeometry& box)
    : cfg_(cfg),
      box_(box),
      standstill_((cfg_.validate(), cfg_), (box_.validate(), box_)),
      flips_(cfg_.settle_s, cfg_.flip_max_s, box_.sample_rate_hz) {
  q_rate_dps2_per_s_ = cfg_.q_dps2_per_s();
  x_.setZero();
  x_.head<kStateDim>().setConstant(cfg_.initial_bias_dps);
  P_.setZero();
  P_.diagonal().head<kStateDim>().setConstant(cfg_.initial_sigma_dps * cfg_.initial_sigma_dps);
  // the temperature coefficients start at 0 with the spec's sigma; off, they stay exactly 0
  P_.diagonal().segment<6>(kTempCoef1.start).setConstant(cfg_.temp_coef_sigma_dps_per_degc *
                                                          cfg_.temp_coef_sigma_dps_per_degc);
  // a calibrated start (calib.yaml from a self-calibration): its values and sigma (floored)
  if (has_temp_states() && cfg_.calibration.has_temp_coef) {
    for (int i = 0; i < 2; ++i) {
      const auto iu = static_cast<std::size_t>(i);
      x_.segment<3>(kTempCoef1.start + 3 * i) = cfg_.calibration.temp_coef_dps_per_degc[iu];
      P_.diagonal().segment<3>(kTempCoef1.start + 3 * i) =
          cfg_.calibration.temp_coef_sigma_dps_per_degc[iu].cwiseAbs2().cwiseMax(cfg_.variance_floor_dps2);
    }
  }
  // the g-sensitivities start at 0 with the spec's sigma in self-calibrating mode, else stay 0
  if (has_gsens_states()) {
    P_.diagonal().segment<18>(kGSens1.start).setConstant(cfg_.gsens_sigma_dps_per_g * cfg_.gsens_sigma_dps_per_g);
  }
  if (has_scale_states()) {
    P_.diagonal().segment<18>(kScale1.start).setConstant(cfg_.scale_misalign_sigma_frac * cfg_.scale_misalign_sigma_frac);
  }
  if (has_stop_states()) {
    P_.diagonal().segment<4>(kStopAngle.start).setConstant(cfg_.flip_angle_sigma_deg * cfg_.flip_angle_sigma_deg);
  }
  use_calibration_prior();
  gate1_ = cfg_.nis_gate_probability < 1.0 ? chi2_quantile(cfg_.nis_gate_probability, 1.0)
                                           : std::numeric_limits<double>::infinity();
  gate3_ = cfg_.nis_gate_probability < 1.0 ? chi2_quantile(cfg_.nis_gate_probability, 3.0)
                                           : std::numeric_limits<double>::infinity();
  gate6_ = cfg_.nis_gate_probability < 1.0 ? chi2_quantile(cfg_.nis_gate_probability, 6.0)
                                           : std::numeric_limits<double>::infinity();
  gate4_ = cfg_.nis_gate_probability < 1.0 ? chi2_quantile(cfg_.nis_gate_probability, 4.0)
                                           : std::numeric_limits<double>::infinity();
}

// --calib (docs/estimator.md section 1e): a sensor error the filter has states for starts at the
// file's value with the file's sigma (a diagonal prior: the file holds no correlations); one it has
// no states for is a fixed correction: G f subtracted in push(), (I + E)^-1 folded into M
void DriftlessFilter::use_calibration_prior() {
  const Calibration& cal = cfg_.calibration;
  fixed_g_ = cal.has_g_sensitivity() && !has_gsens_states();
  fixed_e_ = cal.has_scale_misalign && !has_scale_states();
  const auto start = [this](Eigen::Index o, const Eigen::Matrix3d& value, const Eigen::Matrix3d* sigma) {
    Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(x_.data() + o) = value;
    if (sigma == nullptr) return;
    const Eigen::Matrix<double, 3, 3, Eigen::RowMajor> var = sigma->cwiseAbs2();
    P_.diagonal().segment<9>(o) = Eigen::Map<const Eigen::Matrix<double, 9, 1>>(var.data());
  };
  for (int i = 0; i < 2; ++i) {
    const auto iu = static_cast<std::size_t>(i);
    if (has_gsens_states()) start(kGSens1.start + 9 * i, cal.G_dps_per_g[iu], cal.has_g_sigma ? &cal.G_sigma_dps_per_g[iu] : nullptr);
    if (has_scale_states() && cal.has_scale_misalign) start(kScale1.start + 9 * i, cal.E_frac[iu], &cal.E_sigma_frac[iu]);
    fixed_E_inv_[iu] = fixed_e_ ? Eigen::Matrix3d((Eigen::Matrix3d::Identity() + cal.E_frac[iu]).inverse())
                                : Eigen::Matrix3d::Identity();
  }
  // the end stops: the states start at the file's angles with its sigma, else M turns to them
  fixed_stops_ = cal.has_end_stops && !has_stop_states();
  if (has_stop_states() && cal.has_end_stops) {
    x_.segment<4>(kStopAngle.start) = cal.end_stop_deg;
    P_.diagonal().segment<4>(kStopAngle.start) = cal.end_stop_sigma_deg.cwiseAbs2();
  }
}

void DriftlessFilter::on_source_switch(const BoxGeometry* box) {
  if (box != nullptr) {
    BoxGeometry b = *box;
    b.validate();
    box_ = b;
    cache_deg_ = {kNaN, kNaN};
  }
  standstill_.restart(box_);
  flips_.reset();
  prev_res_.valid = false;
  dwell_ = StandstillSegment{};
  dwell_recent_.clear();
  dwell_quiet_since_s_ = kNaN;
  last_t_s_ = kNaN;
  // P and x stay; the time base of the prediction restarts with the next sample
  t_filter_s_ = kNaN;
  ++counters_.source_switches;
}

Eigen::Matrix3d DriftlessFilter::body_from_sensor(int sensor, double plat_deg) const {
  const std::size_t i = sensor == 1 ? 0 : 1;
  if (cache_deg_[i] == plat_deg) return cache_M_[i];
  const auto& list = sensor == 1 ? cfg_.calibration.sensor1 : cfg_.calibration.sensor2;
  // fixed end-stop errors from --calib (no end-stop states): the sensor rests at plat + d
  const double d_deg = fixed_stops_ ? cfg_.calibration.end_stop_deg[stop_index(sensor, plat_deg) - kStopAngle.start] : 0.0;
  Eigen::Matrix3d M = geo::rot_about_axis_deg(sensor == 1 ? box_.hinge1_axis : box_.hinge2_axis, plat_deg + d_deg);
  double best = cfg_.calibration.match_tolerance_deg;
  for (const auto& p : list) {
    const double d = std::fabs(p.plat_deg - plat_deg);
    if (d <= best) {
      best = d;
      M = p.M_body_from_sensor;
    }
  }
  // a fixed scale/misalignment from --calib: y = (I + E) M^-1 w + ..., so M (I + E)^-1 replaces M
  if (fixed_e_) M = M * fixed_E_inv_[i];
  cache_deg_[i] = plat_deg;
  cache_M_[i] = M;
  return M;
}

void DriftlessFilter::predict_to(double t_s) {
  // A = I: the bias random walk only grows P (eq. (3)); Q = K^2 dt per axis
  if (finite(t_filter_s_) && t_s > t_filter_s_) {
    P_.diagonal().head<kStateDim>().array() += q_rate_dps2_per_s_ * (t_s - t_filter_s_);
  }
  t_filter_s_ = t_s;
}

// the bias follows the temperature: b_i += k_i dT_i, so x <- F x, P <- F P F^T with
// F = [I D; 0 I], D = diag(dT_1 I3, dT_2 I3) (a sensor whose temperature is unknown keeps its own)
void DriftlessFilter::predict_temperature(double temp1_c, double temp2_c) {
  if (!has_temp_states()) return;
  const std::array<double, 2> temp{temp1_c, temp2_c};
  Eigen::Matrix<double, 6, 1> d = Eigen::Matrix<double, 6, 1>::Zero();
  for (std::size_t i = 0; i < 2; ++i) {
    if (!finite(temp[i])) continue;
    if (finite(temp_ref_c_[i])) d.segment<3>(3 * static_cast<Eigen::Index>(i)).setConstant(temp[i] - temp_ref_c_[i]);
    temp_ref_c_[i] = temp[i];
  }
  if (d.isZero(0.0)) return;
  const Eigen::Index k0 = kTempCoef1.start;
  x_.head<kStateDim>() += d.cwiseProduct(x_.segment<6>(k0));
  // P <- F P F^T = P + E P + P E^T + E P E^T with E = F - I (D in the bias rows, k columns)
  const auto D = d.asDiagonal();
  const Eigen::Matrix<double, 6, kFullStateDim> EP = D * P_.middleRows<6>(k0);
  const Matrix6d Pkk = P_.block<6, 6>(k0, k0);
  P_.topRows<6>() += EP;
  P_.leftCols<6>() += EP.transpose();
  P_.topLeftCorner<6, 6>() += D * Pkk * D;
}

// the correction o_i = b_i + k_i (T_i - T_ref_i) + G_i f_i that state `x` (bias referred to
// `temp_ref`) applies to sample s: the filter's own state, or a smoothed one (set_output_state)
Vector6d DriftlessFilter::bias_at(const Sample& s, const StateVector& x, const std::array<double, 2>& temp_ref) const {
  Vector6d b = x.head<kStateDim>();
  if (has_temp_states()) {
    const std::array<double, 2> temp{s.temp1_c, s.temp2_c};
    for (std::size_t i = 0; i < 2; ++i) {
      if (!finite(temp[i]) || !finite(temp_ref[i])) continue;
      const Eigen::Index o = 3 * static_cast<Eigen::Index>(i);
      b.segment<3>(o) += (temp[i] - temp_ref[i]) * x.segment<3>(kTempCoef1.start + o);
    }
  }
  if (has_gsens_states()) {
    // self-calibration: the sample's own specific force, else the last update's
    const std::array<const Eigen::Vector3d*, 2> acc{&s.accel1_mps2, &s.accel2_mps2};
    for (int i = 0; i < 2; ++i) {
      const std::size_t u = static_cast<std::size_t>(i);
      const Eigen::Vector3d f = acc[u]->allFinite() ? Eigen::Vector3d(*acc[u] / kStandardGravityMps2) : last_f_g_[u];
      const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> G(x.data() + kGSens1.start + 9 * i);
      if (f.allFinite()) b.segment<3>(3 * i) += G * f;
    }
  }
  return b;
}

namespace {
// d(M G f)/d vec(G) for row-major vec(G) (estimator/flip_update.hpp)
Eigen::Matrix<double, 3, 9> gsens_jacobian(const Eigen::Matrix3d& M, const Eigen::Vector3d& f_g) {
  return matrix_error_jacobian(M, f_g);
}
}  // namespace

Eigen::Matrix3d DriftlessFilter::g_sensitivity_dps_per_g(int sensor) const {
  const Eigen::Index o = sensor == 1 ? kGSens1.start : kGSens2.start;
  return Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(x_.data() + o);
}

Eigen::Matrix3d DriftlessFilter::g_sensitivity_sigma_dps_per_g(int sensor) const {
  const Eigen::Index o = sensor == 1 ? kGSens1.start : kGSens2.start;
  const Eigen::Matrix<double, 9, 1> sd = P_.diagonal().segment<9>(o).cwiseSqrt();
  return Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(sd.data());
}

Eigen::Matrix3d DriftlessFilter::scale_misalign(int sensor) const {
  const Eigen::Index o = sensor == 1 ? kScale1.start : kScale2.start;
  return Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(x_.data() + o);
}

Eigen::Matrix3d DriftlessFilter::scale_misalign_sigma(int sensor) const {
  const Eigen::Index o = sensor == 1 ? kScale1.start : kScale2.start;
  const Eigen::Matrix<double, 9, 1> sd = P_.diagonal().segment<9>(o).cwiseSqrt();
  return Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(sd.data());
}

Vector6d DriftlessFilter::correction_sigma_dps() const {
  if (!has_gsens_states()) return sigma_dps();
  // o_i = b_i + G_i f_i: row r of J = e_r plus f_i^T in the columns of G_i's row r (row-major vec,
  // as gsens_jacobian), so diag(J P J^T)_r = P_rr + 2 f^T P_(g, r) + f^T P_(g, g) f with g those
  // three columns: the product's 6 diagonal entries, not its 6x52x52 (called on every sample)
  Vector6d var = P_.diagonal().head<6>();
  for (int i = 0; i < 2; ++i) {
    const Eigen::Vector3d& f = last_f_g_[static_cast<std::size_t>(i)];
    if (!f.allFinite()) continue;
    for (int r = 0; r < 3; ++r) {
      const Eigen::Index b = 3 * i + r, g = (i == 0 ? kGSens1.start : kGSens2.start) + 3 * r;
      var[b] += 2.0 * f.dot(P_.block<3, 1>(g, b)) + f.dot(P_.block<3, 3>(g, g) * f);
    }
  }
  return var.cwiseSqrt();
}

// a window [t_first, t_last] averaged by a measurement made at t_update >= t_last: the mean is
// b(t_update) - u with u = (1/T) int (b(t_update) - b(t)) dt, so Var(u) = q (T/3 + g) and
// Cov(u, J) = q (T/2 + g) with g = t_update - t_last and J the walk since t_first, which the
// prior's error holds: no update inside the window observed the residual's directions (a box
// dwell inside a standstill measures the sum of the two sensors' rates, the standstill their
// difference; section 1h)
DriftlessFilter::WindowWander DriftlessFilter::window_wander(double t_first_s, double t_last_s, double t_update_s) {
  const double T = t_last_s - t_first_s;
  if (!(T > 0.0)) return {};
  const double g = finite(t_update_s) ? std::max(0.0, t_update_s - t_last_s) : 0.0;
  return {0.5 * T + g, T / 3.0 + g};
}

bool DriftlessFilter::update(const Rows& r, const Rows& H, const Rows& R, UpdateRecord& rec, bool may_relock,
                             WindowWander wander) {
  const int D = int(r.rows());
  // P here is P_k + Q_k (predict_to ran); the recursion of section 2, S^-1 through a Cholesky solve.
  // A window average (section 1h): the noise -H_b u is correlated with the prior's error,
  // C = Cov(e, n) = -q c H_b^T, so P H^T + C replaces P H^T and S = H P H^T + H C + C^T H^T + R
  // + q v H_b H_b^T; the gain and both covariance forms below take them as they are
  Eigen::MatrixXd PHt = P_ * H.transpose();
  Eigen::MatrixXd S = R;
  if (wander.c_s > 0.0 || wander.v_s > 0.0) {
    const Eigen::MatrixXd Hb = H.leftCols(kStateDim);
    PHt.topRows(kStateDim) -= (q_rate_dps2_per_s_ * wander.c_s) * Hb.transpose();
    S += (q_rate_dps2_per_s_ * (wander.v_s - wander.c_s)) * Hb * Hb.transpose();  // + C^T H^T here, H C below
  }
  S += H * PHt;
  Eigen::LLT<Eigen::MatrixXd> llt(S);
  const Eigen::VectorXd innov = r - H * x_;
  rec.dim = D;
  rec.innovation_dps.setZero();
  rec.innovation_dps.head(D) = innov;
  rec.nis_gate = D == 1 ? gate1_ : D == 3 ? gate3_ : D == 4 ? gate4_ : gate6_;
  if (llt.info() != Eigen::Success) {
    rec.nis = kNaN;
    return false;
  }
  rec.nis = innov.dot(llt.solve(innov));
  if (!(rec.nis <= rec.nis_gate)) {
    if (!may_relock) return false;
    // an outlier is rejected once or twice; a run of rejections means the state lost lock
    // (a bias step, another sensor after a source switch): widen P by the innovation, re-lock
    ++consecutive_rejections_;
    if (cfg_.gate_relock_after <= 0 || consecutive_rejections_ < cfg_.gate_relock_after ||
        !std::isfinite(rec.nis)) {
      return false;
    }
    P_.diagonal().head<kStateDim>().array() += innov.squaredNorm();
    ++counters_.relocks;
    rec.relocked = true;
    rec.relock_nis = rec.nis;
    // one try on the widened P: the part of the innovation outside H's range (a rank-deficient
    // stacked H, a residual the model cannot explain) does not shrink with P, so a second re-lock
    // from here would recurse without end
    return update(r, H, R, rec, /*may_relock=*/false, wander);
  }
  consecutive_rejections_ = 0;
  // an offline smoother keeps the state before the gain (the prediction) and after it
  std::unique_ptr<std::pair<StateVector, StateMatrix>> prior;
  if (observer_ != nullptr) prior = std::make_unique<std::pair<StateVector, StateMatrix>>(x_, P_);
  // W = (P + Q) H^T S^-1
  const Eigen::MatrixXd W = llt.solve(PHt.transpose()).transpose();
  x_ += W * innov;
  if (cfg_.covariance_update == CovarianceUpdate::kJoseph) {
    // (I - W H) P (I - W H)^T + W R W^T multiplied out, P H^T = PHt: P - W (H P) - (W (H P))^T +
    // W S W^T, O(n^2 D) instead of the O(n^3) of the two 48 x 48 products
    const StateMatrix WHP = W * PHt.transpose();
    P_ += W * S * W.transpose() - WHP - WHP.transpose();
  } else {
    if (wander.c_s > 0.0) P_ -= W * PHt.transpose();  // (I - W H) P - W C^T
    else P_ = (StateMatrix::Identity() - W * H) * P_;  // as printed
  }
  P_ = (0.5 * (P_ + P_.transpose())).eval();  // eval: no aliasing with the transpose
  for (int i = 0; i < kStateDim; ++i) P_(i, i) = std::max(P_(i, i), cfg_.variance_floor_dps2);
  if (observer_ != nullptr) observer_->on_accepted_update({t_filter_s_, temp_ref_c_, &prior->first, &prior->second, &x_, &P_});
  return true;
}

void DriftlessFilter::emit_update(const UpdateRecord& in, bool accepted) {
  last_update_ = in;
  last_update_.index = counters_.updates;
  last_update_.accepted = accepted;
  last_update_.bias_dps = bias_dps();
  last_update_.sigma_dps = sigma_dps();
  ++counters_.updates;
  if (!accepted) ++counters_.rejected;
}

// paper mode: does the standstill rest where eq. (5) says (pattern `pattern`, +-flip_angle_deg)?
// Both are counted for the health verdict (a schedule or rest angles that are not the paper's)
void DriftlessFilter::check_paper_position(double plat1_deg, double plat2_deg, int pattern) {
  if (!finite(plat1_deg) || !finite(plat2_deg)) return;
  ++counters_.paper_standstills;
  if (eq5_pattern_of(plat1_deg, plat2_deg) != pattern) ++counters_.schedule_mismatches;
  for (double p : {plat1_deg, plat2_deg}) {
    if (std::abs(std::abs(p) - box_.flip_angle_deg) <= cfg_.calibration.match_tolerance_deg) continue;
    if (counters_.rest_angle_mismatches == 0) counters_.rest_angle_mismatch_deg = p;
    ++counters_.rest_angle_mismatches;
    break;
  }
}

// paper mode: a standstill that could not be used still advances eq. (5)'s counter
void DriftlessFilter::skip_paper_step() {
  prev_res_.valid = false;
  if (cfg_.mode == FilterMode::kPaper && paper_k_ >= 0) ++paper_k_;
}

// turns a standstill's averages into an update; returns +1 accepted, -1 rejected, 0 none
int DriftlessFilter::use_segment(const StandstillSegment& s) {
  const double rate_hz = standstill_.rate_hz(s);
  // positions used for H: measured (general) or eq. (5)'s sequence (paper)
  double p1 = s.plat1_deg, p2 = s.plat2_deg;
  int pattern = 0;
  if (cfg_.mode == FilterMode::kPaper) {
    if (paper_k_ < 0) paper_k_ = finite(p1) && finite(p2) ? eq5_pattern_of(p1, p2) : 0;
    pattern = static_cast<int>(paper_k_ % 4);
    check_paper_position(p1, p2, pattern);
    p1 = eq5_position_deg(pattern, 1, box_.flip_angle_deg);
    p2 = eq5_position_deg(pattern, 2, box_.flip_angle_deg);
    ++paper_k_;
  }
  const Eigen::Matrix3d M1 = body_from_sensor(1, p1);
  const Eigen::Matrix3d M2 = body_from_sensor(2, p2);
  Residual3 cur;
  cur.pattern = pattern;
  residual_rows(s, M1, M2, rate_hz, cur);

  UpdateRecord rec;
  rec.t_s = s.t_last_s;
  rec.t_start_s = s.t_first_s;
  rec.samples = s.n;
  rec.plat1_deg = p1;
  rec.plat2_deg = p2;
  rec.at_end = s.end == SegmentEnd::kFinish;
  // general mode: the average measures the bias's mean over the standstill; the update is made at
  // its end with the window's wander and its correlation with P (section 1h). Paper mode, as
  // printed: at the midpoint, with the wander about it (q T / 12) in R. The temperature part is
  // k (mean T - reference T) exactly (linear in T): the state moves to the standstill's mean
  // temperatures and stays referred to them after the update
  const bool windowed = cfg_.mode == FilterMode::kGeneral;
  const double t_upd = windowed ? s.t_last_s : 0.5 * (s.t_first_s + s.t_last_s);
  if (s.n_temp > 0) predict_temperature(s.sum_temp1_c / double(s.n_temp), s.sum_temp2_c / double(s.n_temp));
  predict_to(std::max(t_upd, finite(t_filter_s_) ? t_filter_s_ : t_upd));
  const WindowWander wander = windowed ? window_wander(s.t_first_s, s.t_last_s, t_filter_s_) : WindowWander{};
  int result = 0;
  Eigen::Matrix<double, 1, kFullStateDim> h;
  double z = 0.0, var_z = 0.0;
  if (cfg_.mode == FilterMode::kGeneral && cfg_.box_at_rest && rest_row(s, M1, M2, cur.R(0, 0), h, z, var_z)) {
    // a box at rest: the residual stacked with the vertical rate (independent noise, section 1b)
    Eigen::Matrix<double, 4, 1> r4;
    r4 << cur.r, z;
    Eigen::Matrix<double, 4, kFullStateDim> H4;
    H4 << cur.H, h;
    Eigen::Matrix<double, 4, 4> R4 = Eigen::Matrix<double, 4, 4>::Zero();
    R4.topLeftCorner<3, 3>() = cur.R;
    R4(3, 3) = var_z;
    const bool ok = update(r4, H4, R4, rec, true, wander);
    emit_update(rec, ok);
    result = ok ? 1 : -1;
  } else if (cfg_.mode == FilterMode::kGeneral) {
    const bool ok = update(cur.r, cur.H, cur.R, rec, true, wander);
    emit_update(rec, ok);
    result = ok ? 1 : -1;
  } else if (prev_res_.valid && ((prev_res_.pattern + 1) % 4) == pattern) {
    // eq. (5): k = pattern of the earlier standstill; rows [H_prev; H_cur], R block-diagonal as
    // the paper assumes (delta-correlated v_k) although r_prev was already used at k - 1
    Eigen::Matrix<double, 6, 1> r6;
    r6 << prev_res_.r, cur.r;
    Eigen::Matrix<double, 6, kFullStateDim> H6;
    H6 << prev_res_.H, cur.H;
    Eigen::Matrix<double, 6, 6> R6 = Eigen::Matrix<double, 6, 6>::Zero();
    R6.block<3, 3>(0, 0) = prev_res_.R;
    R6.block<3, 3>(3, 3) = cur.R;
    const bool ok = update(r6, H6, R6, rec);
    emit_update(rec, ok);
    result = ok ? 1 : -1;
  }
  prev_res_ = cur;
  predict_to(s.t_last_s);
  if (result != 0) last_update_.sigma_dps = sigma_dps();
  // box dwells are used once the correction is known well below the rest threshold
  if (uses_box_dwells()) dwell_armed_ = correction_sigma_dps().maxCoeff() < 0.1 * cfg_.box_dwell_rate_dps;
  return result;
}

// eq. (2) for one standstill: r = M1 y1 - M2 y2 = M1 (b1 + G1 f1) - M2 (b2 + G2 f2) + noise
void DriftlessFilter::residual_rows(const StandstillSegment& s, const Eigen::Matrix3d& M1, const Eigen::Matrix3d& M2,
                                    double rate_hz, Residual3& cur) {
  cur.valid = true;
  cur.r = M1 * s.mean_gyro1_dps() - M2 * s.mean_gyro2_dps();
  cur.H.setZero();
  cur.H.block<3, 3>(0, kBias1.start) = M1;
  cur.H.block<3, 3>(0, kBias2.start) = -M2;
  if (has_gsens_states() && s.n_accel > 0) {
    const double to_g = 1.0 / (double(s.n_accel) * kStandardGravityMps2);
    last_f_g_ = {s.sum_accel1_mps2 * to_g, s.sum_accel2_mps2 * to_g};
    cur.H.block<3, 9>(0, kGSens1.start) = gsens_jacobian(M1, last_f_g_[0]);
    cur.H.block<3, 9>(0, kGSens2.start) = -gsens_jacobian(M2, last_f_g_[1]);
  }
  // eq. (2)'s noise R1 n1 - R2 n2, averaged over n samples; in paper mode the bias random walk adds
  // q T / 12 (its mean over the standstill scatters about its value at the midpoint; general mode
  // carries that wander in the update itself, section 1h)
  const double wander = cfg_.mode == FilterMode::kPaper ? q_rate_dps2_per_s_ * s.span_s() / 12.0 : 0.0;
  const double var = cfg_.sample_variance_dps2(rate_hz) / double(s.n) + wander;
  cur.R = var * (M1 * M1.transpose() + M2 * M2.transpose());
  if (cfg_.gravity_from_ref_q && s.n_accel > 0) cur.R += unknown_accel_cov_dps2(M1, M2, -1.0, box_rate_dps(s, M1, M2));
  // the end-stop rows need the box rate, so the bias, known first (as for the flips and dwells): a
  // rate from a bias not yet known would pass its error into the end-stop states; until then the
  // rest-angle errors are noise
  if (has_stop_states() && correction_sigma_dps().maxCoeff() < 0.1 * cfg_.box_dwell_rate_dps) stop_rows(s, M1, M2, cur);
  else if (cfg_.mode == FilterMode::kGeneral) add_rest_angle_noise(s, M1, M2, cur.R);
  if (has_scale_states()) scale_rows(s, M1, M2, cur);
}

// gravity from ref_q (no accel columns): the box's own acceleration a (g, box axes) is in the gyros
// (G_i M_i^T a) but not in f_i; it adds D a to M1 y1 + s2 M2 y2, D = M1 G1 M1^T + s2 M2 G2 M2^T. With
// a of variance sa^2 per axis and G_i at its estimate with independent element errors of variance
// P_rc: Cov = sa^2 (D D^T + sum_i M_i diag(sum_c P_i,rc) M_i^T). sa^2 = ref_gravity_accel_sigma^2 +
// (ref_gravity_speed w / g)^2, w the box rate less 3 correction sigma (a bias not yet known is no turn)
Eigen::Matrix3d DriftlessFilter::unknown_accel_cov_dps2(const Eigen::Matrix3d& M1, const Eigen::Matrix3d& M2,
                                                        double s2, const Eigen::Vector3d& w_box_dps) const {
  const double w_radps = std::max(0.0, w_box_dps.norm() - 3.0 * correction_sigma_dps().maxCoeff()) * kRadPerDeg;
  const double turn_g = cfg_.ref_gravity_speed_mps * w_radps / kStandardGravityMps2;
  const double sa2 = cfg_.ref_gravity_accel_sigma_g * cfg_.ref_gravity_accel_sigma_g + turn_g * turn_g;
  using RowMajor3 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;
  const std::array<const Eigen::Matrix3d*, 2> M{&M1, &M2};
  Eigen::Matrix3d D = Eigen::Matrix3d::Zero(), U = Eigen::Matrix3d::Zero();
  for (int i = 0; i < 2; ++i) {
    const Eigen::Index o = i == 0 ? kGSens1.start : kGSens2.start;
    const Eigen::Matrix3d& Mi = *M[static_cast<std::size_t>(i)];
    D += (i == 0 ? 1.0 : s2) * Mi * Eigen::Map<const RowMajor3>(x_.data() + o) * Mi.transpose();
    const Eigen::Matrix<double, 9, 1> p = P_.diagonal().segment<9>(o);
    const Eigen::Vector3d row_sums = Eigen::Map<const RowMajor3>(p.data()).rowwise().sum();
    U += Mi * row_sums.asDiagonal() * Mi.transpose();
  }
  return sa2 * (D * D.transpose() + U);
}

// the box rate over a standstill in box axes at the current correction, as the outputs take it:
// each sensor's mean reading less o_i = b_i + G_i f_i (f_i the standstill's own specific force),
// E_i removed to first order, (I - E_i)(y_i - o_i), fused. Its error is the correction's: with b_i
// alone, a sensor whose G column along gravity is observed (a horizontal hinge) would read its
// G_i f_i (~0.06 deg/s for an MPU6050) as a box rate
Eigen::Vector3d DriftlessFilter::box_rate_dps(const StandstillSegment& s, const Eigen::Matrix3d& M1,
                                              const Eigen::Matrix3d& M2) const {
  std::array<Eigen::Vector3d, 2> u{s.mean_gyro1_dps() - bias1_dps(), s.mean_gyro2_dps() - bias2_dps()};
  const std::array<Eigen::Vector3d, 2> sum_accel{s.sum_accel1_mps2, s.sum_accel2_mps2};
  for (int i = 0; i < 2; ++i) {
    const auto iu = static_cast<std::size_t>(i);
    if (has_gsens_states() && s.n_accel > 0) {
      u[iu] -= g_sensitivity_dps_per_g(i + 1) * (sum_accel[iu] / (double(s.n_accel) * kStandardGravityMps2));
    }
    if (has_scale_states()) u[iu] -= scale_misalign(i + 1) * u[iu];
  }
  return 0.5 * (M1 * u[0] + M2 * u[1]);
}

// end-stop states: a rest angle off by d_i about a_i gives M_i y_i = w - d_i (a_i x w) + ..., so
// r = M1 y1 - M2 y2 gains -d_1 (a_1 x w) + d_2 (a_2 x w) (d in rad; the states are in deg)
void DriftlessFilter::stop_rows(const StandstillSegment& s, const Eigen::Matrix3d& M1, const Eigen::Matrix3d& M2,
                                Residual3& cur) const {
  const Eigen::Vector3d w = box_rate_dps(s, M1, M2);
  if (!w.allFinite() || !std::isfinite(s.plat1_deg) || !std::isfinite(s.plat2_deg)) return;
  cur.H.col(stop_index(1, s.plat1_deg)) = -kRadPerDeg * box_.hinge1_axis.normalized().cross(w);
  cur.H.col(stop_index(2, s.plat2_deg)) = kRadPerDeg * box_.hinge2_axis.normalized().cross(w);
}

// each platform rests at an angle known to flip_angle_sigma_deg only (an end stop's error, a
// reading's): sensor i off by d_i about its hinge a_i reads the box rate turned by d_i, so
// M_i y_i gains d_i (a_i x w) (box axes, w the box rate over the standstill). The error is
// fixed per end stop, but w changes from one standstill to the next: taken as noise, it adds
// sigma^2 (a_i x w)(a_i x w)^T per sensor, w at the current estimate (its error, sigma_b, only
// weakens the first update or two). A static box (w = the Earth rate) adds ~1e-5 deg/s; a box
// turning at a few deg/s over a standstill, as much as the white noise. Calibrated matrices
// (--calib) hold the true angles: no term for a sensor that has them
void DriftlessFilter::add_rest_angle_noise(const StandstillSegment& s, const Eigen::Matrix3d& M1,
                                           const Eigen::Matrix3d& M2, Eigen::Matrix3d& R) const {
  const double sigma_rad = kRadPerDeg * cfg_.flip_angle_sigma_deg;
  if (!(sigma_rad > 0.0)) return;
  const Eigen::Vector3d w = box_rate_dps(s, M1, M2);
  if (!w.allFinite()) return;
  if (cfg_.calibration.sensor1.empty()) {
    const Eigen::Vector3d c = sigma_rad * box_.hinge1_axis.normalized().cross(w);
    R += c * c.transpose();
  }
  if (cfg_.calibration.sensor2.empty()) {
    const Eigen::Vector3d c = sigma_rad * box_.hinge2_axis.normalized().cross(w);
    R += c * c.transpose();
  }
}

// self-calibration: y_i = (I + E_i) w_i + ..., so eq. (2) gains M1 E1 w1 - M2 E2 w2 with w_i the
// true rate over the standstill in sensor-i axes. Averages are linear: the mean rate enters. It is
// taken from the fused body rate at the current correction (box_rate_dps), w_i = M_i^T w (an error
// of the estimate times E is second order). While the correction is not yet known, that error is
// not small: each row of M_i E_i dw carries 3 terms of variance sigma_E^2 sigma_o^2 per sensor,
// added to R (6 sigma_E^2 sigma_o^2, the largest sigmas), sigma_o the correction's (b_i + G_i f_i),
// not the bias's: a zero-g bias unobservable on its own (b_1 with G_1's column along a vertical
// hinge: sigma ~ the G prior, 0.058 deg/s) is no error of the rate. A box that barely turns
// (w ~ the Earth rate) leaves E at its prior; a box turning through a standstill observes the
// sensors' relative E along the axes it turns about (docs/estimator.md section 1c)
void DriftlessFilter::scale_rows(const StandstillSegment& s, const Eigen::Matrix3d& M1, const Eigen::Matrix3d& M2,
                                 Residual3& cur) {
  const double so = correction_sigma_dps().maxCoeff();
  const double se = std::sqrt(P_.diagonal().segment<18>(kScale1.start).maxCoeff());
  cur.R.diagonal().array() += 6.0 * se * se * so * so;
  const Eigen::Vector3d w_body = box_rate_dps(s, M1, M2);
  last_w_dps_ = {M1.transpose() * w_body, M2.transpose() * w_body};
  cur.H.block<3, 9>(0, kScale1.start) = gsens_jacobian(M1, last_w_dps_[0]);
  cur.H.block<3, 9>(0, kScale2.start) = -gsens_jacobian(M2, last_w_dps_[1]);
}

// a box at rest: the mean of the two sensors' rates about "up" is the vertical Earth rate,
// z = up^T (M1 y1 + M2 y2) / 2 - Omega sin(lat) = up^T (M1 o1 + M2 o2) / 2 + noise; its noise is
// independent of eq. (2)'s (Cov = up^T (M1 M1^T - M2 M2^T) / 2 = 0 for rotations). `var_r` is
// one axis of eq. (2)'s R: 2 (sigma^2/n + q T/12), so the mean of two sensors has var_r / 4
bool DriftlessFilter::rest_row(const StandstillSegment& s, const Eigen::Matrix3d& M1, const Eigen::Matrix3d& M2,
                               double var_r, Eigen::Matrix<double, 1, kFullStateDim>& h, double& z,
                               double& var_z) const {
  Eigen::Vector3d up = Eigen::Vector3d::Zero();
  if (s.n_accel > 0) up = M1 * s.sum_accel1_mps2 + M2 * s.sum_accel2_mps2;  // specific force points up
  else if (s.n_up > 0) up = s.sum_up_box;
  if (!(up.norm() > 0.0) || !up.allFinite()) return false;
  up.normalize();
  // the vertical Earth rate Omega sin(lat); a log without latitude_deg: none is assumed, the row
  // takes sin(lat) uniform on [-1, 1] (mean 0, variance 1/3: Omega^2 / 3 enters var_z)
  const bool latitude_known = std::isfinite(box_.latitude_deg);
  const double earth_up_dps = latitude_known ? geo::earth_rate_enu_radps(box_.latitude_deg).z() * kDegPerRad : 0.0;
  const double earth_up_var_dps2 = latitude_known ? 0.0 : std::pow(kEarthRateRadps * kDegPerRad, 2) / 3.0;
  z = 0.5 * up.dot(M1 * s.mean_gyro1_dps() + M2 * s.mean_gyro2_dps()) - earth_up_dps;
  h.setZero();
  h.segment<3>(kBias1.start) = 0.5 * up.transpose() * M1;
  h.segment<3>(kBias2.start) = 0.5 * up.transpose() * M2;
  if (has_gsens_states() && s.n_accel > 0) {
    h.segment<9>(kGSens1.start) = 0.5 * up.transpose() * gsens_jacobian(M1, last_f_g_[0]);
    h.segment<9>(kGSens2.start) = 0.5 * up.transpose() * gsens_jacobian(M2, last_f_g_[1]);
  }
  if (has_scale_states()) {
    h.segment<9>(kScale1.start) = 0.5 * up.transpose() * gsens_jacobian(M1, last_w_dps_[0]);
    h.segment<9>(kScale2.start) = 0.5 * up.transpose() * gsens_jacobian(M2, last_w_dps_[1]);
  }
  var_z = 0.25 * var_r + cfg_.box_rest_rate_sigma_dps * cfg_.box_rest_rate_sigma_dps + earth_up_var_dps2;
  if (cfg_.gravity_from_ref_q && s.n_accel > 0) {
    var_z += 0.25 * up.dot(unknown_accel_cov_dps2(M1, M2, 1.0, box_rate_dps(s, M1, M2)) * up);
  }
  return true;
}

void DriftlessFilter::fuse_rate(const Sample& s, const StandstillStep& st) {
  // between updates the correction follows the sample's temperature (b + k dT)
  // the filter's state, or the smoothed one of set_output_state()
  const StateVector& x = output_x_ != nullptr ? *output_x_ : x_;
  const Vector6d b = bias_at(s, x, output_x_ != nullptr ? *output_temp_ref_ : temp_ref_c_);
  out_.y1c_dps = s.gyro1_dps - b.segment<3>(kBias1.start);
  out_.y2c_dps = s.gyro2_dps - b.segment<3>(kBias2.start);
  if (has_scale_states()) {
    // w_i = (I + E_i)^-1 (y_i - o_i) = (I - E_i) (y_i - o_i) to first order in E
    using RowMajor3 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;
    out_.y1c_dps -= Eigen::Map<const RowMajor3>(x.data() + kScale1.start) * out_.y1c_dps;
    out_.y2c_dps -= Eigen::Map<const RowMajor3>(x.data() + kScale2.start) * out_.y2c_dps;
  }
  out_.plat1_deg = st.plat1_deg;
  out_.plat2_deg = st.plat2_deg;
  out_.at_rest = st.plat1_rest && st.plat2_rest && finite(st.plat1_deg) && finite(st.plat2_deg);
  out_.both_moving = st.both_moving;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero(), raw = Eigen::Vector3d::Zero(),
                  fixed = Eigen::Vector3d::Zero();
  int n = 0;
  // a sensor on a moving platform also reads its hinge rate; only resting ones enter the fusion
  // a rest angle off by d about the hinge a (end-stop states): the sensor's axes are turned by d,
  // so in the axes M assumes it reads y + d (a x y) (first order); y1c/y2c stay in the axes read
  const auto turned = [&](int i, double deg, const Eigen::Vector3d& y) -> Eigen::Vector3d {
    if (!has_stop_states()) return y;
    const Eigen::Vector3d& a = i == 1 ? box_.hinge1_axis : box_.hinge2_axis;
    return y + kRadPerDeg * x(stop_index(i, deg)) * a.normalized().cross(y);
  };
  if (st.plat1_rest && !st.plat1_starting && finite(st.plat1_deg)) {
    const Eigen::Matrix3d M1 = body_from_sensor(1, st.plat1_deg);
    sum += M1 * turned(1, st.plat1_deg, out_.y1c_dps);
    raw += M1 * s.gyro1_dps;
    fixed += M1 * (s.gyro1_dps - fixed_bias_.segment<3>(kBias1.start));
    ++n;
  }
  if (st.plat2_rest && !st.plat2_starting && finite(st.plat2_deg)) {
    const Eigen::Matrix3d M2 = body_from_sensor(2, st.plat2_deg);
    sum += M2 * turned(2, st.plat2_deg, out_.y2c_dps);
    raw += M2 * s.gyro2_dps;
    fixed += M2 * (s.gyro2_dps - fixed_bias_.segment<3>(kBias2.start));
    ++n;
  }
  // no platform rests (both flip at once): a moving sensor whose angle and hinge rate the platform
  // columns give reads M(theta) y = w + theta' a, so w = M(theta) y - theta' a (a turned by M stays a)
  const auto moving = [&](int i, double deg, double rate_dps, const Eigen::Vector3d& yc, const Eigen::Vector3d& y) {
    if (!finite(deg) || !finite(rate_dps)) return;
    const Eigen::Matrix3d M = body_from_sensor(i, deg);
    const Eigen::Vector3d hinge = rate_dps * (i == 1 ? box_.hinge1_axis : box_.hinge2_axis).normalized();
    const Eigen::Vector3d& fb = i == 1 ? fixed_bias_.segment<3>(kBias1.start) : fixed_bias_.segment<3>(kBias2.start);
    sum += M * yc - hinge;
    raw += M * y - hinge;
    fixed += M * (y - fb) - hinge;
    ++n;
  };
  if (n == 0) {
    moving(1, st.plat1_deg, st.plat1_rate_dps, out_.y1c_dps, s.gyro1_dps);
    moving(2, st.plat2_deg, st.plat2_rate_dps, out_.y2c_dps, s.gyro2_dps);
  }
  out_.sensors_fused = n;
  if (n > 0) {
    out_.rate_body_dps = sum / double(n);
    out_.rate_body_raw_dps = raw / double(n);
    out_.rate_body_fixed_dps = fixed / double(n);
  }
}

PushStatus DriftlessFilter::push(const Sample& s) {
  // calibrated g-sensitivity without its states: y <- y - G f / g with the sample's own specific force
  if (fixed_g_) {
    Sample c = s;
    if (s.accel1_mps2.allFinite()) c.gyro1_dps -= cfg_.calibration.G_dps_per_g[0] * (s.accel1_mps2 / kStandardGravityMps2);
    if (s.accel2_mps2.allFinite()) c.gyro2_dps -= cfg_.calibration.G_dps_per_g[1] * (s.accel2_mps2 / kStandardGravityMps2);
    return push_corrected(c);
  }
  return push_corrected(s);
}

PushStatus DriftlessFilter::push_corrected(const Sample& s) {
  ++counters_.samples;
  out_ = SampleOutput{};
  out_.t_s = s.t_s;
  if (!finite(s.t_s) || !s.gyros_finite()) {
    ++counters_.invalid;
    if (uses_flips()) flips_.reset();  // a flip with a hole in it is not integrated
    out_.status = PushStatus::kInvalid;
    return out_.status;
  }
  if (finite(last_t_s_) && !(s.t_s > last_t_s_)) {
    ++counters_.time_not_increasing;
    out_.status = PushStatus::kTimeNotIncreasing;
    return out_.status;
  }
  const double dt = finite(last_t_s_) ? s.t_s - last_t_s_ : kNaN;
  last_t_s_ = s.t_s;
  if (!finite(t_filter_s_)) t_filter_s_ = s.t_s;

  // 1. where are the platforms, are they at rest, did a standstill end?
  const StandstillStep st = standstill_.push(s, dt, bias1_dps(), bias2_dps());
  switch (st.state) {
    case StandstillStep::State::kMoving: out_.status = PushStatus::kMoving; break;
    case StandstillStep::State::kSettling: out_.status = PushStatus::kSettling; break;
    case StandstillStep::State::kAccumulating: out_.status = PushStatus::kAccumulating; break;
  }
  // 2. each standstill handed over becomes an update
  int result = 0;
  if (standstill_.discarded_last()) skip_paper_step();
  for (int i = 0; i < st.closed; ++i) {
    const int r = use_segment(standstill_.closed(i));
    if (r != 0) result = r;
  }
  counters_.standstills_too_short = standstill_.too_short();
  counters_.simultaneous_flips = standstill_.simultaneous_flips();
  if (result != 0) {
    out_.status = result > 0 ? PushStatus::kUpdated : PushStatus::kRejected;
    // the update referred the bias to the standstill's mean temperatures; refer it to this
    // sample's, so bias_dps() is the bias now (an exact linear move, no process noise)
    predict_temperature(s.temp1_c, s.temp2_c);
    last_update_.bias_dps = bias_dps();
    last_update_.sigma_dps = sigma_dps();
  }

  // 3. outputs with the estimate now in force
  fuse_rate(s, st);
  // 4. a flip of one platform that just ended: its integrated readings measure E (section 1f)
  if (uses_flips() && flips_.push(s, dt, st) == FlipWindow::Event::kClosed) {
    use_flip();
    predict_temperature(s.temp1_c, s.temp2_c);
  }
  // 5. a box dwell (box_dwell_updates): its vertical rate is the Earth's
  if (uses_box_dwells()) track_box_dwell(s);
  return out_.status;
}

PushStatus DriftlessFilter::finish() {
  const int n = standstill_.finish();
  if (standstill_.discarded_last()) skip_paper_step();
  counters_.standstills_too_short = standstill_.too_short();
  int result = 0;
  for (int i = 0; i < n; ++i) {
    const int r = use_segment(standstill_.closed(i));
    if (r != 0) result = r;
  }
  if (uses_box_dwells()) close_box_dwell(kNaN, kNaN);  // a box still at the end of the stream
  return result > 0 ? PushStatus::kUpdated : result < 0 ? PushStatus::kRejected : PushStatus::kMoving;
}

// ---------------------------------------------------------------------------------------------
// box dwells (docs/estimator.md section 1d): the box pauses with both platforms at rest; its
// vertical rate is then the Earth's, which observes what both sensors share in box axes (their
// common g-sensitivity along gravity acts like a turn about the vertical: eq. (2) cannot see it)

void DriftlessFilter::DwellTrend::add(double t_s, const Eigen::Vector3d& w) {
  n += 1.0;
  st += t_s;
  stt += t_s * t_s;
  sw += w;
  stw += t_s * w;
  sww += w.cwiseAbs2();
}

double DriftlessFilter::DwellTrend::chi2() const {
  if (n < 4.0) return 0.0;
  const double Stt = stt - st * st / n;
  if (!(Stt > 0.0)) return 0.0;
  const Eigen::Vector3d Stw = stw - st * sw / n, Sww = sww - sw.cwiseAbs2() / n;
  const Eigen::Vector3d slope = Stw / Stt;
  // residual variance about the line per axis; the slope's variance is that over Stt
  const Eigen::Vector3d var = (Sww - slope.cwiseProduct(Stw)).cwiseMax(0.0) / (n - 2.0);
  double c = 0.0;
  for (int i = 0; i < 3; ++i) c += var[i] > 0.0 ? slope[i] * slope[i] * Stt / var[i] : 0.0;
  return c;
}

double DriftlessFilter::DwellTrend::change_dps() const {
  if (n < 4.0) return 0.0;
  const double Stt = stt - st * st / n;
  if (!(Stt > 0.0)) return 0.0;
  // the span of t is sqrt(12 Stt / n) for evenly spaced samples
  return ((stw - st * sw / n) / Stt).cwiseAbs().maxCoeff() * std::sqrt(12.0 * Stt / n);
}

bool DriftlessFilter::box_quiet(const Sample& s) const {
  if (!dwell_armed_ || out_.sensors_fused != 2 || !out_.at_rest) return false;
  if (!(out_.rate_body_dps.norm() < cfg_.box_dwell_rate_dps)) return false;
  // without a witness of the turns, |f| within 5 % of 1 g (no linear acceleration) stands for
  // "the box rests"; with one (ref_q), the box may accelerate: the dwell row takes the measured f,
  // and ref_q's mean turn over the dwell decides at its end (use_box_dwell)
  constexpr double kOneGTolerance = 0.05;
  Eigen::Quaterniond q;
  const bool witnessed = ref_q_of(s.ref_q_wxyz, q);
  for (const Eigen::Vector3d* a : {&s.accel1_mps2, &s.accel2_mps2}) {
    if (!a->allFinite()) return false;
    if (!witnessed && !(std::fabs(a->norm() / kStandardGravityMps2 - 1.0) < kOneGTolerance)) return false;
  }
  return true;
}

void DriftlessFilter::track_box_dwell(const Sample& s) {
  const bool quiet = box_quiet(s);
  const bool moved = finite(dwell_quiet_since_s_) &&
                     (out_.plat1_deg != dwell_.plat1_deg || out_.plat2_deg != dwell_.plat2_deg);
  if (!quiet || moved) close_box_dwell(s.temp1_c, s.temp2_c);
  if (!quiet) return;
  if (!finite(dwell_quiet_since_s_)) {
    dwell_quiet_since_s_ = s.t_s;
    dwell_.plat1_deg = out_.plat1_deg;
    dwell_.plat2_deg = out_.plat2_deg;
  }
  if (s.t_s - dwell_quiet_since_s_ < cfg_.box_dwell_margin_s) return;  // the start margin
  dwell_recent_.push_back(
      {s.t_s, s.gyro1_dps, s.gyro2_dps, s.accel1_mps2, s.accel2_mps2, s.temp1_c, s.temp2_c, out_.rate_body_dps,
       s.ref_q_wxyz});
  // samples older than the end margin can no longer be spoiled by the motion that ends the dwell
  while (dwell_recent_.front().t_s < s.t_s - cfg_.box_dwell_margin_s) {
    const DwellSample& d = dwell_recent_.front();
    StandstillSegment one;
    one.t_first_s = one.t_last_s = d.t_s;
    one.n = one.n_accel = 1;
    one.sum_gyro1_dps = d.gyro1_dps;
    one.sum_gyro2_dps = d.gyro2_dps;
    one.sum_accel1_mps2 = d.accel1_mps2;
    one.sum_accel2_mps2 = d.accel2_mps2;
    if (finite(d.temp1_c) && finite(d.temp2_c)) {
      one.n_temp = 1;
      one.sum_temp1_c = d.temp1_c;
      one.sum_temp2_c = d.temp2_c;
    }
    add_segment(dwell_, one);
    dwell_trend_.add(d.t_s - dwell_.t_first_s, d.rate_dps);
    add_dwell_piece(one, d.ref_q_wxyz);
    dwell_recent_.pop_front();
  }
}

// the dwell ends (motion, a platform leaves, the stream ends): used if long enough; the state is
// then referred to the temperatures given (NaN: kept at the dwell's)
void DriftlessFilter::close_box_dwell(double temp1_c, double temp2_c) {
  if (dwell_.n >= 2 && dwell_.span_s() >= cfg_.box_dwell_min_s) {
    if (dwell_trend_.chi2() > kDwellTrendChi2 && dwell_trend_.change_dps() > kDwellTrendChangeDps) {
      ++counters_.box_dwell_moving;
    } else {
      use_box_dwell();
      predict_temperature(temp1_c, temp2_c);
    }
  }
  dwell_ = StandstillSegment{};
  dwell_trend_ = DwellTrend{};
  dwell_pieces_.clear();
  dwell_recent_.clear();
  dwell_quiet_since_s_ = kNaN;
}

void DriftlessFilter::DwellPiece::add(const DwellPiece& later) {
  add_segment(seg, later.seg);
  if (!finite(later.t0_s)) return;
  if (!finite(t0_s)) {
    t0_s = later.t0_s;
    q0 = later.q0;
  }
  t1_s = later.t1_s;
  q1 = later.q1;
}

void DriftlessFilter::add_dwell_piece(const StandstillSegment& one, const Eigen::Vector4d& ref_q_wxyz) {
  if (dwell_pieces_.empty() || one.t_first_s - dwell_pieces_.back().seg.t_first_s >= kDwellPieceS) {
    // the pieces between the edges are merged: at most kDwellEdgePieces, one, kDwellEdgePieces
    constexpr std::size_t kMaxPieces = 2 * kDwellEdgePieces + 1;
    if (dwell_pieces_.size() == kMaxPieces) {
      dwell_pieces_[kDwellEdgePieces].add(dwell_pieces_[kDwellEdgePieces + 1]);
      dwell_pieces_.erase(dwell_pieces_.begin() + kDwellEdgePieces + 1);
    }
    dwell_pieces_.emplace_back();
  }
  DwellPiece& p = dwell_pieces_.back();
  add_segment(p.seg, one);
  Eigen::Quaterniond q;
  if (!ref_q_of(ref_q_wxyz, q)) return;
  if (!finite(p.t0_s)) {
    p.t0_s = one.t_first_s;
    p.q0 = q;
  }
  p.t1_s = one.t_first_s;
  p.q1 = q;
}

// The row takes the box's rate for the Earth's: the box's own mean rate over the samples it averages
// (ref_q's turn from their first to their last, over that span) is an error it would take for the
// sensors'. Above the row's sigma it biases the update by more than the update resolves (a steady
// slow yaw, the end of a turn inside the dwell); below it (a shake that averaged out) it is noise.
// The longest run of the dwell's pieces, dropping up to kDwellEdgePieces at each end, whose turn
// is below its row's sigma: `seg` and that turn; false when there is none
bool DriftlessFilter::unturned_dwell(const Eigen::Matrix3d& M1, const Eigen::Matrix3d& M2, StandstillSegment& seg,
                                     double& turn_dps) const {
  const int n_pieces = static_cast<int>(dwell_pieces_.size());
  bool found = false;
  for (int i = 0; i <= std::min(kDwellEdgePieces, n_pieces - 1); ++i) {
    for (int j = n_pieces - 1; j >= std::max(i, n_pieces - 1 - kDwellEdgePieces); --j) {
      DwellPiece c = dwell_pieces_[static_cast<std::size_t>(i)];
      for (int k = i + 1; k <= j; ++k) c.add(dwell_pieces_[static_cast<std::size_t>(k)]);
      if (c.seg.n < 2 || !(c.seg.span_s() > 0.0) || c.seg.span_s() < cfg_.box_dwell_min_s) continue;
      if (found && c.seg.n <= seg.n) continue;
      const double ref_span_s = c.t1_s - c.t0_s;
      const double turn = ref_span_s > 0.0 ? rotation_deg(c.q0, c.q1).norm() / ref_span_s : 0.0;
      const double var_r = 2.0 * cfg_.sample_variance_dps2(double(c.seg.n - 1) / c.seg.span_s()) / double(c.seg.n);
      Eigen::Matrix<double, 1, kFullStateDim> h;
      double z = 0.0, var_z = 0.0;
      if (!rest_row(c.seg, M1, M2, var_r, h, z, var_z) || turn * turn > var_z) continue;
      // the whole dwell: its own sums (the pieces' add up in another order)
      seg = i == 0 && j == n_pieces - 1 ? dwell_ : c.seg;
      turn_dps = turn;
      found = true;
    }
  }
  return found;
}

void DriftlessFilter::use_box_dwell() {
  const Eigen::Matrix3d M1 = body_from_sensor(1, dwell_.plat1_deg);
  const Eigen::Matrix3d M2 = body_from_sensor(2, dwell_.plat2_deg);
  StandstillSegment seg;
  double turn_dps = 0.0;
  if (!unturned_dwell(M1, M2, seg, turn_dps)) {
    ++counters_.box_dwell_turned;
    return;
  }
  seg.plat1_deg = dwell_.plat1_deg;
  seg.plat2_deg = dwell_.plat2_deg;
  const double to_g = 1.0 / (double(seg.n_accel) * kStandardGravityMps2);
  last_f_g_ = {seg.sum_accel1_mps2 * to_g, seg.sum_accel2_mps2 * to_g};
  // the box turns at the Earth rate only (0.004 deg/s): E times it stays below 1e-4 deg/s, far under
  // a dwell's noise, and a rate taken from a bias not yet known would pass its error into E
  last_w_dps_ = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  if (seg.n_temp > 0) predict_temperature(seg.sum_temp1_c / double(seg.n_temp), seg.sum_temp2_c / double(seg.n_temp));
  // updated at the dwell's end with its window's wander, as the standstills (section 1h)
  predict_to(std::max(seg.t_last_s, finite(t_filter_s_) ? t_filter_s_ : seg.t_last_s));
  const WindowWander wander = window_wander(seg.t_first_s, seg.t_last_s, t_filter_s_);
  // one axis of eq. (2)'s R for this segment (rotations: M1 M1^T + M2 M2^T = 2 I), as rest_row expects
  const double rate_hz = double(seg.n - 1) / seg.span_s();
  const double var_r = 2.0 * cfg_.sample_variance_dps2(rate_hz) / double(seg.n);
  Eigen::Matrix<double, 1, kFullStateDim> h;
  Eigen::Matrix<double, 1, 1> z, var_z;
  if (!rest_row(seg, M1, M2, var_r, h, z(0), var_z(0))) return;
  var_z(0) += turn_dps * turn_dps;  // a turn below the row's sigma (unturned_dwell) is noise
  UpdateRecord rec;  // not emitted: the platform updates' record and counts stay theirs
  const bool ok = update(z, h, var_z, rec, false, wander);
  ++counters_.box_dwell_updates;
  if (!ok) ++counters_.box_dwell_rejected;
  predict_to(std::max(seg.t_last_s, t_filter_s_));
}

// ---------------------------------------------------------------------------------------------
// flip updates (docs/estimator.md section 1f): one platform flipped, the other rested

SensorErrors DriftlessFilter::errors_of(int sensor) const {
  SensorErrors e;
  e.b_dps = x_.segment<3>(sensor == 1 ? kBias1.start : kBias2.start);
  if (has_gsens_states()) e.G_dps_per_g = g_sensitivity_dps_per_g(sensor);
  e.E_frac = scale_misalign(sensor);
  return e;
}

void DriftlessFilter::use_flip() {
  // the profile and the E regressor use the corrected rates: only once the correction is known
  // (as for the box dwells); before, a flip would pass the bias error into E
  if (!(correction_sigma_dps().maxCoeff() < 0.1 * cfg_.box_dwell_rate_dps)) return;
  // a gyro that clipped in the flip integrates a turn short of it: that is no measurement of E
  if (flip_clipped(flips_)) {
    ++counters_.flip_clipped;
    return;
  }
  const int m = flips_.moving(), r = 3 - m;
  FlipModel fm;
  fm.M_moving_start = body_from_sensor(m, flips_.start_deg());
  fm.M_rest = body_from_sensor(r, flips_.rest_deg());
  fm.hinge_box = (m == 1 ? box_.hinge1_axis : box_.hinge2_axis).normalized();
  fm.hinge_rest_box = (m == 1 ? box_.hinge2_axis : box_.hinge1_axis).normalized();
  fm.moving = errors_of(m);
  fm.rest = errors_of(r);
  fm.use_g = has_gsens_states();
  if (fm.use_g) {
    fm.g_var_dps2_per_g2 = P_.diagonal().segment<18>(kGSens1.start).maxCoeff() +
                           x_.segment<18>(kGSens1.start).cwiseAbs2().maxCoeff();
  }
  const double n = double(flips_.samples().size());
  const double rate_hz = n / (flips_.t_end_s() - flips_.t_start_s());
  fm.sample_var_dps2 = cfg_.sample_variance_dps2(std::isfinite(box_.sample_rate_hz) ? box_.sample_rate_hz : rate_hz);
  // with end-stop states the rest angles' errors are states, not noise
  fm.angle_sigma_deg = has_stop_states() ? 0.0 : cfg_.flip_angle_sigma_deg;
  const FlipRows fr = flip_rows(flips_, fm);
  if (!fr.valid) return;
  const auto at = [](StateSlice first, int sensor, Eigen::Index width) { return first.start + width * (sensor - 1); };
  Eigen::Matrix<double, 3, kFullStateDim> H = Eigen::Matrix<double, 3, kFullStateDim>::Zero();
  H.block<3, 3>(0, at(kBias1, m, 3)) = fr.H_b_moving;
  H.block<3, 3>(0, at(kBias1, r, 3)) = fr.H_b_rest;
  if (has_gsens_states() && fr.g_columns) {
    H.block<3, 9>(0, at(kGSens1, m, 9)) = fr.H_G_moving;
    H.block<3, 9>(0, at(kGSens1, r, 9)) = fr.H_G_rest;
  }
  H.block<3, 9>(0, at(kScale1, m, 9)) = fr.H_E_moving;
  H.block<3, 9>(0, at(kScale1, r, 9)) = fr.H_E_rest;
  if (has_stop_states()) {
    H.col(stop_index(m, flips_.end_deg())) += fr.H_stop_end;
    H.col(stop_index(m, flips_.start_deg())) += fr.H_stop_start;
    H.col(stop_index(r, flips_.rest_deg())) += fr.H_stop_rest;
  }
  // the regressors use the corrected rates: the correction's error times E (3 terms per sensor, as
  // in scale_rows)
  const double so = correction_sigma_dps().maxCoeff();
  const double se = std::sqrt(P_.diagonal().segment<18>(kScale1.start).maxCoeff());
  Eigen::Matrix3d R = fr.R_deg2;
  R.diagonal().array() += 6.0 * se * se * so * so * fr.span_s * fr.span_s;
  predict_to(std::max(0.5 * (flips_.t_start_s() + flips_.t_end_s()), t_filter_s_));
  UpdateRecord rec;  // not emitted: the standstill updates' record and counts stay theirs
  const bool ok = update(fr.z_deg, H, R, rec, false);
  ++counters_.flip_updates;
  if (!ok) ++counters_.flip_rejected;
  if (ok) counters_.flip_nis_sum += rec.nis;
  predict_to(std::max(flips_.t_end_s(), t_filter_s_));
}

}  // namespace driftless::est
