// The weighted least-squares machinery of the noise fit (estimator/allan_fit.cpp): the data, a
// non-negative least-squares solve and the iteratively reweighted fit in log space. Internal header.
#pragma once

#include <vector>

#include <Eigen/Core>

#include "estimator/allan_fit.hpp"

namespace driftless::est::fit_detail {

/// The points of a curve the fit uses: tau (s), Allan variance (units^2), weight = edf / 2
/// (var(ln avar) = 2 / edf), and the correlation of each point's estimate with the next one's
/// (neighbouring taus share data; generalised least squares with a Markov-chain correlation).
struct FitData {
  std::vector<double> tau_s, avar, weight, edf, rho_next;
  double tau0_s = 0.01;
  std::size_t size() const { return tau_s.size(); }
};

/// The nonlinear shape parameters of a design: the white noise's low-pass time constant and the
/// Gauss-Markov correlation time (s; 0 = pure white / no Gauss-Markov).
struct Shape {
  double white_tau_s = 0.0;
  double gm_tau_s = 0.0;
};

/// The result of one weighted fit.
struct Solution {
  NoiseModel model;
  std::vector<NoiseTerm> columns;
  Eigen::VectorXd coef;        // per column, >= 0
  Eigen::MatrixXd cov;         // covariance of the active coef, (J^T J)^-1 at the solution (no inflation)
  Eigen::VectorXd free_coef;   // inactive columns: the unconstrained estimate (may be < 0); active: coef
  Eigen::VectorXd free_var;    // its variance (active: the diagonal of cov)
  double chi2 = 0.0;           // sum weight (ln model - ln avar)^2
  double dof = 0.0;            // points - active columns
  std::vector<double> residual;  // per point, sqrt(weight) (ln avar - ln model) (not whitened)
  bool ok = false;
};

/// Lawson-Hanson non-negative least squares: min |A x - b| subject to x >= 0.
Eigen::VectorXd nnls(const Eigen::MatrixXd& A, const Eigen::VectorXd& b);

/// Fits coefficients >= 0 of the terms `columns` (each at most once) by iteratively reweighted least
/// squares in log space: minimises sum weight (ln model - ln avar)^2. `start` (optional) seeds the
/// weights with a previous solution's model.
Solution fit_columns(const FitData& d, const std::vector<NoiseTerm>& columns, const Shape& shape,
                     const NoiseModel* start = nullptr);

/// Value of term t's basis (coefficient 1) at tau.
double basis(NoiseTerm t, double tau_s, double tau0_s, const Shape& shape);

}  // namespace driftless::est::fit_detail
