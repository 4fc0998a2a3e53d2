// Chi-square tail probabilities, densities and quantiles for the likelihood-ratio tests
// (Boost.Math's incomplete gamma functions, with errors returned, not thrown).
#pragma once

namespace mpm {

// P(X > x) for X ~ chi-square(dof). Allocation free; NaN for invalid input.
double chi_square_survival(double x, double dof) noexcept;
// The density of chi-square(dof) at x. Allocation free; NaN for invalid input.
double chi_square_density(double x, double dof) noexcept;
// x such that P(X > x) = alpha. For setup (thresholds), not the hot path.
double chi_square_quantile_upper(double alpha, double dof) noexcept;

}  // namespace mpm
