#include "estimator/allan_fit_solve.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Dense>

namespace driftless::est::fit_detail {
namespace {

// least squares on the columns in `active` (others zero); columns are pre-scaled
Eigen::VectorXd solve_active(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, const std::vector<bool>& active) {
  std::vector<int> idx;
  for (int j = 0; j < static_cast<int>(active.size()); ++j) {
    if (active[j]) idx.push_back(j);
  }
  Eigen::VectorXd x = Eigen::VectorXd::Zero(A.cols());
  if (idx.empty()) return x;
  Eigen::MatrixXd As(A.rows(), static_cast<Eigen::Index>(idx.size()));
  for (std::size_t k = 0; k < idx.size(); ++k) As.col(static_cast<Eigen::Index>(k)) = A.col(idx[k]);
  const Eigen::VectorXd z = As.colPivHouseholderQr().solve(b);
  for (std::size_t k = 0; k < idx.size(); ++k) x[idx[k]] = z[static_cast<Eigen::Index>(k)];
  return x;
}

// multiplies by L^-1 where L L^T is the Markov-chain correlation of neighbouring taus
// (corr(i, i+1) = rho[i]): row 0 stays, row k becomes (row_k - rho row_{k-1}) / sqrt(1 - rho^2)
template <class M>
void whiten(const std::vector<double>& rho, M& a) {
  for (Eigen::Index k = a.rows() - 1; k >= 1; --k) {
    const double r = rho[static_cast<std::size_t>(k - 1)];
    a.row(k) = (a.row(k) - r * a.row(k - 1)) / std::sqrt(1.0 - r * r);
  }
}

}  // namespace

Eigen::VectorXd nnls(const Eigen::MatrixXd& A_in, const Eigen::VectorXd& b) {
  const Eigen::Index p = A_in.cols();
  // scale columns to unit norm: the bases differ by many orders of magnitude
  Eigen::VectorXd scale(p);
  Eigen::MatrixXd A = A_in;
  for (Eigen::Index j = 0; j < p; ++j) {
    const double nrm = A.col(j).norm();
    scale[j] = nrm > 0.0 ? nrm : 1.0;
    A.col(j) /= scale[j];
  }
  Eigen::VectorXd x = Eigen::VectorXd::Zero(p);
  std::vector<bool> active(static_cast<std::size_t>(p), false);
  const double tol = 1e-12 * std::max(1.0, b.norm());
  for (int outer = 0; outer < 3 * p + 10; ++outer) {
    const Eigen::VectorXd w = A.transpose() * (b - A * x);
    Eigen::Index t = -1;
    double best = tol;
    for (Eigen::Index j = 0; j < p; ++j) {
      if (!active[j] && w[j] > best) best = w[j], t = j;
    }
    if (t < 0) break;
    active[t] = true;
    for (int inner = 0; inner < 3 * p + 10; ++inner) {
      const Eigen::VectorXd z = solve_active(A, b, active);
      bool feasible = true;
      double alpha = 1.0;
      for (Eigen::Index j = 0; j < p; ++j) {
        if (active[j] && z[j] <= 0.0) {
          feasible = false;
          alpha = std::min(alpha, x[j] / (x[j] - z[j]));
        }
      }
      if (feasible) {
        x = z;
        break;
      }
      x += alpha * (z - x);
      for (Eigen::Index j = 0; j < p; ++j) {
        if (active[j] && x[j] <= 1e-15) active[j] = false, x[j] = 0.0;
      }
    }
  }
  for (Eigen::Index j = 0; j < p; ++j) x[j] /= scale[j];
  return x;
}

double basis(NoiseTerm t, double tau_s, double tau0_s, const Shape& shape) {
  NoiseModel unit;
  unit.tau0_s = tau0_s;
  unit.gm_tau_s = shape.gm_tau_s;
  unit.white_tau_s = shape.white_tau_s;
  unit.coef[static_cast<int>(t)] = 1.0;
  return unit.term_avar(t, tau_s);
}

Solution fit_columns(const FitData& d, const std::vector<NoiseTerm>& columns, const Shape& shape,
                     const NoiseModel* start) {
  const auto n = static_cast<Eigen::Index>(d.size());
  const auto p = static_cast<Eigen::Index>(columns.size());
  Solution s;
  s.columns = columns;
  if (n == 0 || p == 0) return s;
  Eigen::MatrixXd F(n, p);
  for (Eigen::Index i = 0; i < n; ++i) {
    for (Eigen::Index j = 0; j < p; ++j) F(i, j) = basis(columns[j], d.tau_s[i], d.tau0_s, shape);
  }
  const Eigen::Map<const Eigen::VectorXd> y(d.avar.data(), n);
  const Eigen::Map<const Eigen::VectorXd> w(d.weight.data(), n);
  // log-space least squares, linearised: residual (model - y) / model_prev, weight w
  Eigen::VectorXd prev = y, coef = Eigen::VectorXd::Zero(p);
  if (start != nullptr) {
    for (Eigen::Index i = 0; i < n; ++i) prev[i] = std::max(start->avar(d.tau_s[i]), 1e-3 * y[i]);
  }
  for (int iter = 0; iter < 40; ++iter) {
    const Eigen::VectorXd rw = w.cwiseSqrt().cwiseQuotient(prev);
    Eigen::MatrixXd A = rw.asDiagonal() * F;
    Eigen::VectorXd b = rw.cwiseProduct(y);
    whiten(d.rho_next, A);
    whiten(d.rho_next, b);
    const Eigen::VectorXd next = nnls(A, b);
    const double change = (next - coef).cwiseAbs().maxCoeff();
    coef = next;
    const Eigen::VectorXd model = F * coef;
    for (Eigen::Index i = 0; i < n; ++i) prev[i] = std::max(model[i], 1e-3 * y[i]);
    if (change <= 1e-10 * std::max(1e-300, coef.cwiseAbs().maxCoeff())) break;
  }
  s.coef = coef;
  const Eigen::VectorXd model = F * coef;
  s.residual.resize(d.size());
  s.ok = true;
  for (Eigen::Index i = 0; i < n; ++i) {
    s.ok = s.ok && model[i] > 0.0;
    s.residual[i] = model[i] > 0.0 ? std::sqrt(w[i]) * std::log(y[i] / model[i]) : 0.0;
  }
  Eigen::VectorXd r = Eigen::Map<const Eigen::VectorXd>(s.residual.data(), n);
  whiten(d.rho_next, r);
  s.chi2 = r.squaredNorm();
  // covariances in log space at the solution (Jacobian F_ij / model_i, weighted): the active
  // coefficients conditional on the inactive ones being zero; each inactive one alone added to
  // the active set, with its unconstrained one-step estimate (for upper bounds)
  const Eigen::VectorXd rw = w.cwiseSqrt().cwiseQuotient(model.cwiseMax(1e-300));
  Eigen::MatrixXd J = rw.asDiagonal() * F;
  whiten(d.rho_next, J);
  std::vector<int> act;
  for (Eigen::Index j = 0; j < p; ++j) {
    if (coef[j] > 0.0) act.push_back(static_cast<int>(j));
  }
  s.cov = Eigen::MatrixXd::Zero(p, p);
  s.free_coef = coef;
  s.free_var = Eigen::VectorXd::Zero(p);
  auto sub_cov = [&](const std::vector<int>& cols, Eigen::VectorXd* step) {
    Eigen::MatrixXd Js(n, static_cast<Eigen::Index>(cols.size()));
    for (std::size_t k = 0; k < cols.size(); ++k) Js.col(static_cast<Eigen::Index>(k)) = J.col(cols[k]);
    const Eigen::MatrixXd C = (Js.transpose() * Js).completeOrthogonalDecomposition().pseudoInverse();
    if (step != nullptr) *step = C * (Js.transpose() * r);
    return C;
  };
  const Eigen::MatrixXd Ca = sub_cov(act, nullptr);
  for (std::size_t a = 0; a < act.size(); ++a) {
    for (std::size_t b = 0; b < act.size(); ++b) s.cov(act[a], act[b]) = Ca(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b));
    s.free_var[act[a]] = Ca(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(a));
  }
  for (Eigen::Index j = 0; j < p; ++j) {
    if (coef[j] > 0.0) continue;
    std::vector<int> cols = act;
    cols.push_back(static_cast<int>(j));
    Eigen::VectorXd step;
    const Eigen::MatrixXd C = sub_cov(cols, &step);
    const auto last = static_cast<Eigen::Index>(cols.size() - 1);
    s.free_var[j] = C(last, last);
    s.free_coef[j] = step[last];
  }
  s.dof = static_cast<double>(n - static_cast<Eigen::Index>(act.size()));
  s.model.tau0_s = d.tau0_s;
  s.model.gm_tau_s = shape.gm_tau_s;
  s.model.white_tau_s = shape.white_tau_s;
  for (Eigen::Index j = 0; j < p; ++j) s.model.coef[static_cast<int>(columns[j])] = coef[j];
  return s;
}

}  // namespace driftless::est::fit_detail
