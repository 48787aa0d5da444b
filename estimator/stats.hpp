// Small statistics helpers the estimator and the Allan analysis share: chi-square and normal
// quantiles (for confidence intervals, NEES/NIS bands). Standard library only.
#pragma once

namespace driftless::est {

/// Regularised lower incomplete gamma P(a, x), a > 0, x >= 0.
double regularized_gamma_p(double a, double x);
/// Chi-square cumulative distribution with `dof` (> 0, may be fractional) degrees of freedom.
double chi2_cdf(double x, double dof);
/// Chi-square quantile: the x with chi2_cdf(x, dof) = p, 0 < p < 1 (bisection, relative 1e-12).
double chi2_quantile(double p, double dof);
/// Standard normal quantile (Acklam's rational approximation refined by one Halley step).
double normal_quantile(double p);

}  // namespace driftless::est
