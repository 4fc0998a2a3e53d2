#include "core/state_space.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <stdexcept>
#include <vector>

#include <unsupported/Eigen/MatrixFunctions>

namespace mpm {
namespace {

using Roots = std::vector<std::complex<double>>;

// Monic polynomial with these roots, highest power first (real parts: the
// roots come in conjugate pairs).
std::vector<double> poly(const Roots& roots) {
  std::vector<std::complex<double>> c{1.0};
  for (const auto& r : roots) {
    c.push_back(0.0);
    for (std::size_t k = c.size() - 1; k > 0; --k) c[k] -= r * c[k - 1];
  }
  std::vector<double> out(c.size());
  for (std::size_t k = 0; k < c.size(); ++k) out[k] = c[k].real();
  return out;
}

Roots eigenvalues(const Eigen::MatrixXd& a) {
  Roots out;
  if (a.rows() == 0) return out;
  const Eigen::VectorXcd e = a.eigenvalues();
  out.assign(e.data(), e.data() + e.size());
  return out;
}

// Roots of c0 z^d + ... + cd (c0 != 0), by the companion matrix.
Roots poly_roots(const std::vector<double>& c) {
  const auto d = static_cast<Eigen::Index>(c.size()) - 1;
  Eigen::MatrixXd companion = Eigen::MatrixXd::Zero(d, d);
  for (Eigen::Index j = 0; j < d; ++j) companion(0, j) = -c[static_cast<std::size_t>(j) + 1] / c[0];
  for (Eigen::Index i = 1; i < d; ++i) companion(i, i - 1) = 1.0;
  return eigenvalues(companion);
}

// num/den in q^-1 from numerator and denominator roots in z: den = prod(z - p),
// num = gain z^-lead prod(z - r), both over z^n. Common roots cancelled.
DiscreteTf from_roots(double gain, std::size_t lead, Roots zeros, Roots poles) {
  // Repeated poles come out of the eigen-solver only to about sqrt(eps).
  constexpr double kCancel = 1e-6;
  for (auto z = zeros.begin(); z != zeros.end();) {
    const auto p = std::min_element(poles.begin(), poles.end(), [&](const auto& a, const auto& b) {
      return std::abs(a - *z) < std::abs(b - *z);
    });
    if (p != poles.end() && std::abs(*p - *z) < kCancel * std::max(1.0, std::abs(*p))) {
      poles.erase(p);
      z = zeros.erase(z);
    } else {
      ++z;
    }
  }
  DiscreteTf tf;
  tf.den = poly(poles);
  tf.num.assign(lead, 0.0);
  for (const double c : poly(zeros)) tf.num.push_back(gain * c);
  tf.num.resize(std::max(tf.num.size(), tf.den.size()), 0.0);
  tf.normalise();
  return tf;
}

// det(zI - m1) - det(zI - a) + d det(zI - a), highest power first, and the
// transfer function it gives over det(zI - a).
DiscreteTf rank_one_tf(const Eigen::MatrixXd& a, const Eigen::MatrixXd& a_minus_bc, double d) {
  const Roots poles = eigenvalues(a);
  const std::vector<double> pa = poly(poles), pm = poly(eigenvalues(a_minus_bc));
  std::vector<double> num(pa.size());
  double scale = 0.0;
  for (std::size_t k = 0; k < pa.size(); ++k) {
    num[k] = pm[k] - pa[k] + d * pa[k];
    scale = std::max(scale, std::abs(pm[k]) + std::abs(pa[k]));
  }
  // What the subtraction leaves of exact zeros is rounding.
  for (double& c : num)
    if (std::abs(c) < 1e-12 * scale) c = 0.0;
  const auto first = std::find_if(num.begin(), num.end(), [](double c) { return c != 0.0; });
  if (first == num.end()) return DiscreteTf{};
  const std::vector<double> rest(first, num.end());
  return from_roots(rest.front(), static_cast<std::size_t>(first - num.begin()), poly_roots(rest), poles);
}

void check_finite(const Eigen::MatrixXd& m) {
  if (!m.allFinite()) throw std::invalid_argument("matrix entries must be finite");
}

}  // namespace

StateSpace discretize_zoh(const StateSpace& c, double ts) {
  if (!(ts > 0.0) || !std::isfinite(ts)) throw std::invalid_argument("sample time must be > 0");
  for (const auto* m : {&c.A, &c.B, &c.C, &c.D, &c.G}) check_finite(*m);
  const Eigen::Index n = c.A.rows(), m = c.B.cols(), nw = c.G.cols();
  Eigen::MatrixXd aug = Eigen::MatrixXd::Zero(n + m + nw, n + m + nw);
  aug.topLeftCorner(n, n) = c.A * ts;
  aug.block(0, n, n, m) = c.B * ts;
  if (nw > 0) aug.block(0, n + m, n, nw) = c.G * ts;
  const Eigen::MatrixXd e = aug.exp();
  StateSpace d = c;
  d.A = e.topLeftCorner(n, n);
  d.B = e.block(0, n, n, m);
  if (nw > 0) d.G = e.block(0, n + m, n, nw);
  return d;
}

DiscreteTf channel_tf(const StateSpace& s, std::size_t output, std::size_t input) {
  const auto j = static_cast<Eigen::Index>(output), i = static_cast<Eigen::Index>(input);
  return rank_one_tf(s.A, s.A - s.B.col(i) * s.C.row(j), s.D(j, i));
}

NoiseModel innovations_model(const StateSpace& s, std::size_t output) {
  const auto j = static_cast<Eigen::Index>(output);
  const Eigen::RowVectorXd c = s.C.row(j);
  const double r = s.R(j);
  const Eigen::MatrixXd q = s.G * s.W * s.G.transpose();
  // The Riccati recursion of the one-step predictor, from P = Q.
  Eigen::MatrixXd p = q;
  Eigen::VectorXd k;
  double innovation = 0.0;
  bool settled = false;
  for (int it = 0; it < 100000 && !settled; ++it) {
    innovation = (c * p * c.transpose())(0, 0) + r;
    if (!(innovation > 0.0)) throw std::invalid_argument("the innovation variance is zero (give v > 0)");
    k = s.A * p * c.transpose() / innovation;
    Eigen::MatrixXd next = s.A * p * s.A.transpose() + q - k * innovation * k.transpose();
    next = 0.5 * (next + next.transpose());
    settled = (next - p).norm() <= 1e-13 * std::max(1.0, next.norm());
    p = std::move(next);
  }
  if (!settled || !p.allFinite())
    throw std::invalid_argument("the Kalman filter of this output does not settle (is the disturbance part unstable?)");
  NoiseModel nm;
  nm.tf = rank_one_tf(s.A, s.A - k * c, 1.0);
  nm.variance = innovation;
  return nm;
}

}  // namespace mpm
