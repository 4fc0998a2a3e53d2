#include "core/noise_filter.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace mpm {

DiscreteTf inverse(const DiscreteTf& n) {
  DiscreteTf tf = n;
  tf.normalise();
  if (tf.delay != 0) throw std::invalid_argument("noise model must have no delay to be invertible");
  if (tf.num.empty() || tf.num[0] == 0.0)
    throw std::invalid_argument("noise model num[0] must be nonzero to be invertible");
  DiscreteTf inv;
  inv.num = tf.den;
  inv.den = tf.num;
  inv.delay = 0;
  inv.normalise();
  if (!inv.is_stable()) throw std::invalid_argument("noise model is not minimum phase: its inverse is unstable");
  return inv;
}

double noise_output_variance(const DiscreteTf& n, double a_variance) {
  if (!n.is_stable()) return INFINITY;
  DiscreteFilter f(n);
  double energy = 0.0;
  for (int k = 0; k < 1'000'000; ++k) {
    const double h = f.step(k == 0 ? 1.0 : 0.0);
    energy += h * h;
    if (k > static_cast<int>(n.num.size() + n.den.size()) + n.delay && h * h < 1e-14 * energy) break;
  }
  return a_variance * energy;
}

std::vector<double> inverse_noise_ar_coefficients(const DiscreteTf& n, int order) {
  if (order < 0) throw std::invalid_argument("order must be >= 0");
  DiscreteFilter inv(inverse(n));
  // Impulse response h of N^-1; d_t = -sum_{j>=1} (h_j / h_0) d_{t-j} + a_t / h_0.
  std::vector<double> h(static_cast<std::size_t>(order) + 1);
  for (std::size_t k = 0; k < h.size(); ++k) h[k] = inv.step(k == 0 ? 1.0 : 0.0);
  std::vector<double> g(static_cast<std::size_t>(order));
  for (std::size_t j = 0; j < g.size(); ++j) g[j] = -h[j + 1] / h[0];
  return g;
}

}  // namespace mpm
