// Calibration fit on the pan/tilt unit: the paper's top-to-top averaging and a full linear
// least-squares fit with the Earth rate removed. Conventions: see calibration.hpp.
#include "estimator/calibration.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include <Eigen/Cholesky>
#include <Eigen/Dense>
#include <Eigen/SVD>

#include "estimator/geometry.hpp"
#include "estimator/sample.hpp"

namespace driftless::est {
namespace {

constexpr const char* kAxisName[3] = {"x", "y", "z"};

std::string sensor_pos_name(int sensor, int pos) {
  return "sensor " + std::to_string(sensor + 1) + " at " + position_name(pos);
}

std::string vec_text(const Eigen::Vector3d& v) {
  std::ostringstream s;
  s.precision(3);
  s << "[" << v.x() << ", " << v.y() << ", " << v.z() << "]";
  return s.str();
}

// the orientation that turns the box about a box axis (XY plane level -> z, YZ -> x, XZ -> y)
std::string orientation_for_axis(int axis) {
  static const char* kName[3] = {"YZ", "XZ", "XY"};
  return kName[axis];
}

// nearest rotation to a 3x3 matrix (polar decomposition via SVD)
Eigen::Matrix3d nearest_rotation(const Eigen::Matrix3d& A) {
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(A, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0) D(2, 2) = -1.0;
  return svd.matrixU() * D * svd.matrixV().transpose();
}

// vec(M) covariance from vec(M_inv) covariance: dM = -M dM_inv M, vec(dM) = -(M^T kron M) vec(dM_inv)
Eigen::Matrix<double, 9, 9> inverse_cov(const Eigen::Matrix3d& M,
                                        const Eigen::Matrix<double, 9, 9>& cov_inv) {
  Eigen::Matrix<double, 9, 9> J;
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) J.block<3, 3>(3 * r, 3 * c) = -M.transpose()(r, c) * M;
  return J * cov_inv * J.transpose();
}

Eigen::Matrix3d sigma_of(const Eigen::Matrix<double, 9, 9>& cov) {
  Eigen::Matrix3d s;
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) s(r, c) = std::sqrt(std::max(0.0, cov(3 * c + r, 3 * c + r)));
  return s;
}

// the segments in which `sensor` rests at `pos`, checked for observability of all of M
std::vector<const CalibSegment*> segments_for(const std::vector<CalibSegment>& segments,
                                              int sensor, int pos, const CalibFitOptions& opts) {
  std::vector<const CalibSegment*> used;
  for (const auto& s : segments)
    if (s.pos[sensor] == pos) used.push_back(&s);
  const std::string who = sensor_pos_name(sensor, pos);
  if (used.empty()) {
    throw std::invalid_argument("calibration: no segment has " + who +
                                "; all 9 coefficients of its M are unobservable (the plan needs "
                                "the XY, YZ and XZ orientations at that end stop)");
  }
  // the table axes seen at this end stop must span box space: each axis fixes one column of M^-1
  Eigen::Matrix3d gram = Eigen::Matrix3d::Zero();
  for (const auto* s : used) gram += s->axis_box * s->axis_box.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(gram);
  std::string missing;
  for (int k = 0; k < 3; ++k) {
    if (std::sqrt(std::max(0.0, eig.eigenvalues()[k])) >= opts.min_axis_singular_value) continue;
    const Eigen::Vector3d v = eig.eigenvectors().col(k);
    int dominant = 0;
    v.cwiseAbs().maxCoeff(&dominant);
    const bool aligned = std::abs(v[dominant]) > 0.99;
    if (!missing.empty()) missing += "; ";
    if (aligned) {
      const std::string a = kAxisName[dominant];
      missing += "the response to box " + a + " rate, M^-1[x," + a + "], M^-1[y," + a +
                 "], M^-1[z," + a + "] (column " + a + " of M^-1, so every coefficient of M " +
                 "mixes it) -- no segment turns the box about " + a + ": add the " +
                 orientation_for_axis(dominant) + " orientation at " + position_name(pos);
    } else {
      missing += "the response to box rate along " + vec_text(v) +
                 " -- no segment turns the box about that direction";
    }
  }
  if (!missing.empty()) {
    throw std::invalid_argument("calibration: " + who + ": unobservable coefficient(s): " +
                                missing);
  }
  for (const auto* s : used) {
    std::size_t n_pos = 0, n_neg = 0;
    for (const auto& x : s->samples) (x.sign > 0 ? n_pos : n_neg)++;
    if (n_pos < opts.min_samples_per_level || n_neg < opts.min_samples_per_level) {
      throw std::invalid_argument(
          "calibration: segment '" + s->name + "' has " + std::to_string(n_pos) +
          " samples at +rate and " + std::to_string(n_neg) + " at -rate on the plateaus; need " +
          std::to_string(opts.min_samples_per_level) + " of each (is the segment too short, or " +
          "the settle time too long?)");
    }
  }
  return used;
}

// the paper: top = mean output while turning at +rate, bottom = at -rate;
// M^-1 a = (top - bottom) / (2 rate), bias = (top + bottom) / 2 (Earth rate included)
SensorPositionFit fit_top_to_top(const std::vector<const CalibSegment*>& used, int sensor) {
  const int m = static_cast<int>(used.size());
  Eigen::Matrix3Xd A(3, m), D(3, m), D_var(3, m);
  SensorPositionFit out;
  for (int o = 0; o < m; ++o) {
    const CalibSegment& s = *used[o];
    Eigen::Vector3d sum[2] = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
    Eigen::Vector3d sq[2] = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
    double n[2] = {0, 0};
    for (const auto& x : s.samples) {
      const int k = x.sign > 0 ? 0 : 1;
      sum[k] += x.gyro_dps[sensor];
      n[k] += 1;
    }
    const Eigen::Vector3d top = sum[0] / n[0], bottom = sum[1] / n[1];
    for (const auto& x : s.samples) {
      const int k = x.sign > 0 ? 0 : 1;
      sq[k] += (x.gyro_dps[sensor] - (k == 0 ? top : bottom)).cwiseAbs2();
    }
    // variance of each level's mean (white noise about the plateau)
    const Eigen::Vector3d var_top = sq[0] / ((n[0] - 1) * n[0]);
    const Eigen::Vector3d var_bot = sq[1] / ((n[1] - 1) * n[1]);
    A.col(o) = s.axis_box;
    D.col(o) = (top - bottom) / (2.0 * s.rate_dps);
    D_var.col(o) = (var_top + var_bot) / (4.0 * s.rate_dps * s.rate_dps);
    out.biases.push_back({s.name, 0.5 * (top + bottom), 0.5 * (var_top + var_bot).cwiseSqrt()});
  }
  // M^-1 A = D  ->  M^-1 = D A^+ (A^+ = A^T (A A^T)^-1; equal to A^-1 for three segments)
  const Eigen::Matrix<double, Eigen::Dynamic, 3> A_pinv =
      A.transpose() * (A * A.transpose()).inverse();
  out.M_inv = D * A_pinv;
  // var(M^-1[j,k]) = sum_o var(D[j,o]) A^+[o,k]^2; rows independent, columns correlated
  for (int j = 0; j < 3; ++j)
    for (int k1 = 0; k1 < 3; ++k1)
      for (int k2 = 0; k2 < 3; ++k2) {
        double c = 0.0;
        for (int o = 0; o < m; ++o) c += D_var(j, o) * A_pinv(o, k1) * A_pinv(o, k2);
        out.M_inv_cov(3 * k1 + j, 3 * k2 + j) = c;
      }
  // residuals against the square-wave model
  Eigen::Vector3d ss = Eigen::Vector3d::Zero();
  for (int o = 0; o < m; ++o) {
    const CalibSegment& s = *used[o];
    for (const auto& x : s.samples) {
      const Eigen::Vector3d pred =
          out.M_inv * (x.sign * s.rate_dps * s.axis_box) + out.biases[o].bias_dps;
      const Eigen::Vector3d e = (x.gyro_dps[sensor] - pred).cwiseAbs();
      ss += e.cwiseAbs2();
      out.residual_max_dps = out.residual_max_dps.cwiseMax(e);
      ++out.n_samples;
    }
  }
  out.residual_rms_dps = (ss / static_cast<double>(out.n_samples)).cwiseSqrt();
  return out;
}

// least squares per output axis j: y_j = M^-1[j,:] (sign rate a + w_earth) + b_{o,j};
// unknowns: the row of M^-1 and one bias per segment (bias drift between remountings)
SensorPositionFit fit_least_squares(const std::vector<const CalibSegment*>& used, int sensor,
                                    int pos) {
  const int m = static_cast<int>(used.size());
  const int p = 3 + m;
  Eigen::MatrixXd XtX = Eigen::MatrixXd::Zero(p, p);
  Eigen::MatrixXd XtY = Eigen::MatrixXd::Zero(p, 3);
  Eigen::VectorXd x(p);
  std::size_t n = 0;
  for (int o = 0; o < m; ++o) {
    const CalibSegment& s = *used[o];
    for (const auto& smp : s.samples) {
      x.setZero();
      x.head<3>() = smp.sign * s.rate_dps * s.axis_box + smp.earth_rate_box_dps;
      x[3 + o] = 1.0;
      XtX.selfadjointView<Eigen::Lower>().rankUpdate(x);
      XtY += x * smp.gyro_dps[sensor].transpose();
      ++n;
    }
  }
  XtX = XtX.selfadjointView<Eigen::Lower>();
  const Eigen::LLT<Eigen::MatrixXd> llt(XtX);
  if (llt.info() != Eigen::Success) {
    throw std::invalid_argument("calibration: " + sensor_pos_name(sensor, pos) +
                                ": least-squares normal equations are singular");
  }
  const Eigen::MatrixXd beta = llt.solve(XtY);  // p x 3: column j = output axis j
  const Eigen::MatrixXd XtX_inv = llt.solve(Eigen::MatrixXd::Identity(p, p));
  SensorPositionFit out;
  out.M_inv = beta.topRows<3>().transpose();
  // residuals: second pass
  Eigen::Vector3d ss = Eigen::Vector3d::Zero();
  for (int o = 0; o < m; ++o) {
    const CalibSegment& s = *used[o];
    for (const auto& smp : s.samples) {
      const Eigen::Vector3d u = smp.sign * s.rate_dps * s.axis_box + smp.earth_rate_box_dps;
      const Eigen::Vector3d pred = out.M_inv * u + beta.row(3 + o).transpose();
      const Eigen::Vector3d e = (smp.gyro_dps[sensor] - pred).cwiseAbs();
      ss += e.cwiseAbs2();
      out.residual_max_dps = out.residual_max_dps.cwiseMax(e);
    }
  }
  out.n_samples = n;
  out.residual_rms_dps = (ss / static_cast<double>(n)).cwiseSqrt();
  const Eigen::Vector3d noise_var = ss / static_cast<double>(n - static_cast<std::size_t>(p));
  // cov(row j of beta) = sigma_j^2 (X^T X)^-1
  for (int j = 0; j < 3; ++j)
    for (int k1 = 0; k1 < 3; ++k1)
      for (int k2 = 0; k2 < 3; ++k2)
        out.M_inv_cov(3 * k1 + j, 3 * k2 + j) = noise_var[j] * XtX_inv(k1, k2);
  for (int o = 0; o < m; ++o) {
    const Eigen::Vector3d sd = (noise_var * XtX_inv(3 + o, 3 + o)).cwiseSqrt();
    out.biases.push_back({used[o]->name, beta.row(3 + o).transpose(), sd});
  }
  return out;
}

}  // namespace

int position_index(double plat_deg, double tol_deg) {
  if (!std::isfinite(plat_deg)) return -1;
  if (std::abs(plat_deg - 90.0) <= tol_deg) return kPosPlus90;
  if (std::abs(plat_deg + 90.0) <= tol_deg) return kPosMinus90;
  return -1;
}

std::string position_name(int pos) { return pos == kPosPlus90 ? "+90" : "-90"; }

std::string method_name(CalibMethod m) {
  return m == CalibMethod::kTopToTop ? "top_to_top" : "least_squares";
}

CalibMatrices CalibMatrices::nominal(const Eigen::Vector3d& hinge1_axis,
                                     const Eigen::Vector3d& hinge2_axis) {
  CalibMatrices c;
  const Eigen::Vector3d axes[2] = {hinge1_axis, hinge2_axis};
  for (int i = 0; i < 2; ++i)
    for (int p = 0; p < 2; ++p) c.M(i, p) = geo::rot_about_axis_deg(axes[i], position_deg(p));
  return c;
}

void CalibMatrices::validate() const {
  for (int i = 0; i < 2; ++i)
    for (int p = 0; p < 2; ++p) {
      const Eigen::Matrix3d& m = M(i, p);
      if (!m.allFinite()) {
        throw std::invalid_argument("calibration matrix M of " + sensor_pos_name(i, p) +
                                    " holds a non-finite value");
      }
      const Eigen::JacobiSVD<Eigen::Matrix3d> svd(m);
      const auto& s = svd.singularValues();
      if (s[2] < 0.5 || s[0] > 2.0) {
        throw std::invalid_argument(
            "calibration matrix M of " + sensor_pos_name(i, p) + " has singular values " +
            vec_text(s) + "; expected a near-rotation (0.5..2): not a gyro calibration matrix");
      }
    }
}

Calibration to_filter_calibration(const CalibMatrices& m) {
  m.validate();
  Calibration c;
  for (int p = 0; p < 2; ++p) {
    c.sensor1.push_back({position_deg(p), m.M(0, p)});
    c.sensor2.push_back({position_deg(p), m.M(1, p)});
  }
  return c;
}

Eigen::Vector3d sensor_output_dps(const Eigen::Matrix3d& M_box_from_sensor,
                                  const Eigen::Vector3d& w_body_dps,
                                  const Eigen::Vector3d& bias_dps) {
  return M_box_from_sensor.partialPivLu().solve(w_body_dps) + bias_dps;
}

Eigen::Vector3d box_rate_dps(const Eigen::Matrix3d& M_box_from_sensor, const Eigen::Vector3d& y_dps,
                             const Eigen::Vector3d& bias_dps) {
  return M_box_from_sensor * (y_dps - bias_dps);
}

void CalibFitOptions::validate() const {
  if (min_samples_per_level < 2) {
    throw std::invalid_argument("calibration: min_samples_per_level must be >= 2");
  }
  if (!(min_axis_singular_value > 0.0 && min_axis_singular_value <= 1.0)) {
    throw std::invalid_argument("calibration: min_axis_singular_value must be in (0, 1]");
  }
}

CalibMatrices CalibFit::matrices() const {
  CalibMatrices c;
  for (int i = 0; i < 2; ++i)
    for (int p = 0; p < 2; ++p) c.M(i, p) = fit[i][p].M;
  return c;
}

CalibFit fit_calibration(const std::vector<CalibSegment>& segments, const CalibFitOptions& opts) {
  opts.validate();
  for (const auto& s : segments) {
    if (!(s.rate_dps > 0.0) || !std::isfinite(s.rate_dps)) {
      throw std::invalid_argument("calibration: segment '" + s.name +
                                  "': rate_dps must be positive");
    }
    if (std::abs(s.axis_box.norm() - 1.0) > 1e-6) {
      throw std::invalid_argument("calibration: segment '" + s.name +
                                  "': axis_box must be a unit vector, got " + vec_text(s.axis_box));
    }
    for (int i = 0; i < 2; ++i)
      if (s.pos[i] != kPosMinus90 && s.pos[i] != kPosPlus90) {
        throw std::invalid_argument("calibration: segment '" + s.name + "': sensor " +
                                    std::to_string(i + 1) + " is not at an end stop");
      }
  }
  CalibFit out;
  out.method = opts.method;
  for (int i = 0; i < 2; ++i)
    for (int p = 0; p < 2; ++p) {
      const auto used = segments_for(segments, i, p, opts);
      SensorPositionFit f = opts.method == CalibMethod::kTopToTop ? fit_top_to_top(used, i)
                                                                  : fit_least_squares(used, i, p);
      const Eigen::FullPivLU<Eigen::Matrix3d> lu(f.M_inv);
      if (!lu.isInvertible()) {
        throw std::invalid_argument("calibration: " + sensor_pos_name(i, p) +
                                    ": the fitted M^-1 is singular (is the sensor dead on one "
                                    "axis, or the log from another rig?)");
      }
      f.M = lu.inverse();
      f.M_inv_sigma = sigma_of(f.M_inv_cov);
      f.M_sigma = sigma_of(inverse_cov(f.M, f.M_inv_cov));
      out.fit[i][p] = std::move(f);
    }
  return out;
}

CalibErrors describe_errors(const CalibMatrices& m, int sensor, const Eigen::Vector3d& hinge_axis) {
  const Eigen::Vector3d a = hinge_axis.normalized();
  CalibErrors e;
  Eigen::Vector3d nonorth = Eigen::Vector3d::Zero();
  for (int p = 0; p < 2; ++p) {
    const Eigen::Matrix3d M = m.M(sensor, p);
    const Eigen::Matrix3d Minv = M.inverse();
    const Eigen::Matrix3d R_nom = geo::rot_about_axis_deg(a, position_deg(p));
    Eigen::Vector3d dir[3];
    for (int j = 0; j < 3; ++j) {
      const Eigen::Vector3d row = Minv.row(j).transpose();
      e.scale_error[j] += 0.5 * (row.norm() - 1.0);
      dir[j] = row.normalized();
      const double c = std::clamp(dir[j].dot(R_nom.col(j)), -1.0, 1.0);
      e.axis_error_deg[p][j] = std::acos(c) * kDegPerRad;
    }
    const std::pair<int, int> pairs[3] = {{0, 1}, {1, 2}, {0, 2}};
    for (int k = 0; k < 3; ++k) {
      const double c = std::clamp(dir[pairs[k].first].dot(dir[pairs[k].second]), -1.0, 1.0);
      nonorth[k] += 0.5 * (90.0 - std::acos(c) * kDegPerRad);
    }
    // rotation part of M (box_from_sensor) against the nominal, in box axes
    e.tilt_box_deg[p] = geo::rotvec_rad(Eigen::Matrix3d(nearest_rotation(M) * R_nom.transpose())) * kDegPerRad;
  }
  e.nonorthogonality_deg = nonorth;
  // travel: M_-90 M_+90^-1 = T_-90 T_+90^T = Rot(a, th_-90 - th_+90); against Rot(a, -180)
  const Eigen::Matrix3d X = m.M(sensor, kPosMinus90) * m.M(sensor, kPosPlus90).inverse();
  const Eigen::Matrix3d D = geo::rot_about_axis_deg(a, 180.0) * nearest_rotation(X);  // = Rot(a, -travel_err)
  const Eigen::Vector3d rv = geo::rotvec_rad(D) * kDegPerRad;
  e.travel_error_deg = -rv.dot(a);
  e.travel_offaxis_deg = (rv - rv.dot(a) * a).norm();
  return e;
}

GSensitivityFit fit_g_sensitivity(const std::vector<CalibSegment>& segments, const CalibFit& fit) {
  GSensitivityFit g;
  g.valid = true;
  for (int i = 0; i < 2; ++i) {
    const auto iu = static_cast<std::size_t>(i);
    // per segment: [1, f_seg], its temperature and its bias, over both end stops
    std::vector<Eigen::Vector4d> x;
    std::vector<double> temp;
    std::vector<Eigen::Vector3d> y;
    for (const auto& seg : segments) {
      if (!seg.f_mean_g[iu].allFinite()) continue;
      for (const auto& b : fit.fit[iu][static_cast<std::size_t>(seg.pos[iu])].biases) {
        if (b.segment != seg.name) continue;
        x.emplace_back(1.0, seg.f_mean_g[iu].x(), seg.f_mean_g[iu].y(), seg.f_mean_g[iu].z());
        temp.push_back(seg.temp_mean_c[iu]);
        y.push_back(b.bias_dps);
      }
    }
    const std::string who = "sensor " + std::to_string(i + 1);
    if (x.size() < 5) {
      g = GSensitivityFit{};
      g.reason = who + ": " + std::to_string(x.size()) +
                 " segments with accelerometer data; the g-sensitivity fit needs 5 or more";
      return g;
    }
    const auto n = static_cast<Eigen::Index>(x.size());
    Eigen::MatrixXd F(n, 4);
    for (Eigen::Index k = 0; k < n; ++k) F.row(k) = x[static_cast<std::size_t>(k)].transpose();
    // the gravity directions must span 3-D (an offset b0 plus 3 slopes)
    if (Eigen::JacobiSVD<Eigen::MatrixXd>(F).singularValues().minCoeff() < 0.2) {
      g = GSensitivityFit{};
      g.reason = who + ": the segments' gravity directions do not span three axes (use the XY, YZ and XZ "
                       "orientations)";
      return g;
    }
    double t_mean = 0.0, t_min = 1e300, t_max = -1e300;
    bool t_ok = n >= 6;
    for (double t : temp) {
      t_ok = t_ok && std::isfinite(t);
      t_mean += t / static_cast<double>(n);
      t_min = std::min(t_min, t);
      t_max = std::max(t_max, t);
    }
    t_ok = t_ok && t_max - t_min > 0.05;
    if (i == 0) g.temperature_term = t_ok;
    const bool use_t = g.temperature_term && t_ok;
    const Eigen::Index p = use_t ? 5 : 4;
    Eigen::MatrixXd X(n, p), Y(n, 3);
    X.leftCols(4) = F;
    for (Eigen::Index k = 0; k < n; ++k) {
      if (use_t) X(k, 4) = temp[static_cast<std::size_t>(k)] - t_mean;
      Y.row(k) = y[static_cast<std::size_t>(k)].transpose();
    }
    const Eigen::MatrixXd XtX_inv = (X.transpose() * X).inverse();
    const Eigen::MatrixXd beta = XtX_inv * X.transpose() * Y;  // p x 3: rows b0, G^T, (k_T)
    const Eigen::MatrixXd res = Y - X * beta;
    const double dof = static_cast<double>(n - p);
    for (int j = 0; j < 3; ++j) {
      const double var = dof > 0 ? res.col(j).squaredNorm() / dof : kNaN;
      g.residual_rms_dps[iu][j] = std::sqrt(res.col(j).squaredNorm() / static_cast<double>(n));
      g.b0_dps[iu][j] = beta(0, j);
      if (use_t) g.bias_tc_dps_per_degc[iu][j] = beta(4, j);
      for (int c = 0; c < 3; ++c) {
        g.G_dps_per_g[iu](j, c) = beta(1 + c, j);
        g.G_sigma[iu](j, c) = std::sqrt(var * XtX_inv(1 + c, 1 + c));
      }
    }
    g.segments = x.size();
  }
  return g;
}

}  // namespace driftless::est
