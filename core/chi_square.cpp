#include "core/chi_square.hpp"

#include <cmath>

#include <boost/math/policies/policy.hpp>
#include <boost/math/special_functions/gamma.hpp>

namespace mpm {
namespace {

using namespace boost::math::policies;
using NoThrow = policy<domain_error<errno_on_error>, pole_error<errno_on_error>, overflow_error<errno_on_error>,
                       evaluation_error<errno_on_error>, promote_double<false>>;

}  // namespace

double chi_square_survival(double x, double dof) noexcept {
  if (!(dof > 0.0) || std::isnan(x)) return NAN;
  if (x <= 0.0) return 1.0;
  return boost::math::gamma_q(dof / 2.0, x / 2.0, NoThrow());
}

double chi_square_density(double x, double dof) noexcept {
  if (!(dof > 0.0) || std::isnan(x)) return NAN;
  if (x <= 0.0) return x == 0.0 && dof == 2.0 ? 0.5 : 0.0;
  // f(x) = (x/2)^(k/2 - 1) e^(-x/2) / (2 Gamma(k/2)) = gamma_p_derivative(k/2, x/2) / 2
  return 0.5 * boost::math::gamma_p_derivative(dof / 2.0, x / 2.0, NoThrow());
}

double chi_square_quantile_upper(double alpha, double dof) noexcept {
  if (!(dof > 0.0) || !(alpha > 0.0 && alpha < 1.0)) return NAN;
  return 2.0 * boost::math::gamma_q_inv(dof / 2.0, alpha, NoThrow());
}

}  // namespace mpm
