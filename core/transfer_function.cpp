#include "core/transfer_function.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>
#include <unsupported/Eigen/MatrixFunctions>

namespace mpm {
namespace {

bool all_finite(const std::vector<double>& v) {
  return std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); });
}

void trim_trailing_zeros(std::vector<double>& v) {
  while (v.size() > 1 && v.back() == 0.0) v.pop_back();
}

// Polynomial 1 + c1 q^-1 + ... + cn q^-n whose z-roots are `roots`.
std::vector<double> poly_from_roots(const Eigen::VectorXcd& roots) {
  std::vector<std::complex<double>> c{1.0};
  for (Eigen::Index i = 0; i < roots.size(); ++i) {
    c.push_back(0.0);
    for (std::size_t k = c.size() - 1; k > 0; --k) c[k] -= roots[i] * c[k - 1];
  }
  std::vector<double> out(c.size());
  std::transform(c.begin(), c.end(), out.begin(), [](std::complex<double> z) { return z.real(); });
  return out;
}

// Companion-matrix roots of c0 z^n + ... + cn (ascending q^-1 coefficients).
Eigen::VectorXcd z_roots(const std::vector<double>& c) {
  std::size_t n = c.size();
  while (n > 1 && c[n - 1] == 0.0) --n;  // trailing zeros = roots at z = 0; ignore
  if (n <= 1) return {};
  const Eigen::Index deg = static_cast<Eigen::Index>(n - 1);
  Eigen::MatrixXd companion = Eigen::MatrixXd::Zero(deg, deg);
  for (Eigen::Index j = 0; j < deg; ++j) companion(0, j) = -c[static_cast<std::size_t>(j) + 1] / c[0];
  for (Eigen::Index i = 1; i < deg; ++i) companion(i, i - 1) = 1.0;
  return companion.eigenvalues();
}

}  // namespace

void DiscreteTf::normalise() {
  if (den.empty() || den[0] == 0.0) throw std::invalid_argument("den[0] must be nonzero");
  if (num.empty()) num = {0.0};
  if (!all_finite(num) || !all_finite(den)) throw std::invalid_argument("coefficients must be finite");
  if (delay < 0) throw std::invalid_argument("delay must be >= 0");
  const double d0 = den[0];
  for (double& x : num) x /= d0;
  for (double& x : den) x /= d0;
  trim_trailing_zeros(num);
  trim_trailing_zeros(den);
}

bool DiscreteTf::is_zero() const {
  return std::all_of(num.begin(), num.end(), [](double x) { return x == 0.0; });
}

double DiscreteTf::dc_gain() const {
  double n = 0.0, d = 0.0;
  for (double x : num) n += x;
  for (double x : den) d += x;
  if (std::abs(d) < 1e-12) return n >= 0 ? INFINITY : -INFINITY;
  return n / d;
}

std::vector<double> root_magnitudes(const std::vector<double>& ascending) {
  const Eigen::VectorXcd r = z_roots(ascending);
  std::vector<double> out(static_cast<std::size_t>(r.size()));
  for (Eigen::Index i = 0; i < r.size(); ++i) out[static_cast<std::size_t>(i)] = std::abs(r[i]);
  return out;
}

bool DiscreteTf::is_stable() const {
  const auto mags = root_magnitudes(den);
  return std::all_of(mags.begin(), mags.end(), [](double m) { return m < 1.0 - 1e-12; });
}

bool DiscreteTf::has_integrator() const {
  const Eigen::VectorXcd r = z_roots(den);
  for (Eigen::Index i = 0; i < r.size(); ++i)
    if (std::abs(r[i] - std::complex<double>(1.0, 0.0)) < 1e-9) return true;
  return false;
}

// ZOH with a fractional dead time (modified z-transform in state space):
// with tau = d*ts + theta, 0 <= theta < ts, over one sample the delayed input
// is u(k-d-1) for theta seconds, then u(k-d), so
//   x(k+1) = Phi x(k) + Gamma1 u(k-d-1) + Gamma0 u(k-d)
// Markov parameters of C (zI - Phi)^-1 (Gamma0 + Gamma1 z^-1) times the
// characteristic polynomial of Phi give the numerator exactly.
DiscreteTf discretize_zoh(const ContinuousTf& g, double ts) {
  if (!(ts > 0.0) || !std::isfinite(ts)) throw std::invalid_argument("sample time must be > 0");
  if (!(g.dead_time >= 0.0) || !std::isfinite(g.dead_time))
    throw std::invalid_argument("dead_time must be >= 0");
  std::vector<double> num = g.num, den = g.den;
  if (num.empty() || den.empty()) throw std::invalid_argument("num and den must not be empty");
  if (!all_finite(num) || !all_finite(den)) throw std::invalid_argument("coefficients must be finite");
  // Strip leading zeros (highest powers that are zero).
  while (den.size() > 1 && den.front() == 0.0) den.erase(den.begin());
  while (num.size() > 1 && num.front() == 0.0) num.erase(num.begin());
  if (den.front() == 0.0) throw std::invalid_argument("den must not be zero");
  if (num.size() > den.size()) throw std::invalid_argument("improper transfer function (num degree > den degree)");

  DiscreteTf out;
  const double lead = den.front();
  for (double& x : den) x /= lead;
  for (double& x : num) x /= lead;
  const std::size_t n = den.size() - 1;

  int d = static_cast<int>(std::floor(g.dead_time / ts + 1e-9));
  double theta = g.dead_time - d * ts;
  if (theta < 1e-9 * ts) theta = 0.0;

  if (n == 0) {  // pure gain
    out.num = {num[0]};
    out.den = {1.0};
    out.delay = d + (theta > 0.0 ? 1 : 0);
    if (theta > 0.0) {  // gain with fractional delay: split over two samples
      const double f = theta / ts;
      out.num = {num[0] * (1.0 - f), num[0] * f};
      out.delay = d;
    }
    out.normalise();
    return out;
  }

  // Controllable canonical form of num/den (den monic, degree n).
  std::vector<double> b(n + 1, 0.0);  // num padded to degree n, highest first
  std::copy(num.begin(), num.end(), b.begin() + static_cast<long>(n + 1 - num.size()));
  const double dterm = b[0];
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(n));
  Eigen::VectorXd bv = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n));
  Eigen::VectorXd c(static_cast<Eigen::Index>(n));
  for (std::size_t j = 0; j < n; ++j) {
    a(0, static_cast<Eigen::Index>(j)) = -den[j + 1];
    c(static_cast<Eigen::Index>(j)) = b[j + 1] - dterm * den[j + 1];
  }
  for (std::size_t i = 1; i < n; ++i) a(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(i - 1)) = 1.0;
  bv(0) = 1.0;

  // exp([[A, B], [0, 0]] t) = [[e^{At}, int_0^t e^{A s} ds B], [0, 1]]
  const Eigen::Index ni = static_cast<Eigen::Index>(n);
  auto integrate = [&](double t, Eigen::MatrixXd& phi, Eigen::VectorXd& gamma) {
    Eigen::MatrixXd m = Eigen::MatrixXd::Zero(ni + 1, ni + 1);
    m.topLeftCorner(ni, ni) = a * t;
    m.topRightCorner(ni, 1) = bv * t;
    const Eigen::MatrixXd e = m.exp();
    phi = e.topLeftCorner(ni, ni);
    gamma = e.topRightCorner(ni, 1);
  };
  Eigen::MatrixXd phi, phi_rest, phi_theta;
  Eigen::VectorXd gamma_full, gamma0, gamma_theta;
  integrate(ts, phi, gamma_full);
  integrate(ts - theta, phi_rest, gamma0);
  integrate(theta, phi_theta, gamma_theta);
  const Eigen::VectorXd gamma1 = phi_rest * gamma_theta;

  const std::vector<double> den_z = poly_from_roots(phi.eigenvalues());  // size n+1
  // Markov parameters h_1..h_{n+1} of C (zI-Phi)^-1 (Gamma0 + Gamma1 z^-1).
  std::vector<double> h(n + 2, 0.0);
  Eigen::VectorXd p0 = gamma0, p1 = gamma1;  // Phi^{k-1} Gamma0, Phi^{k-2} Gamma1
  h[1] = c.dot(p0);
  for (std::size_t k = 2; k <= n + 1; ++k) {
    p0 = phi * p0;
    h[k] = c.dot(p0) + c.dot(p1);
    p1 = phi * p1;
  }
  std::vector<double> num_z(n + 2, 0.0);  // coefficients of q^0 .. q^-(n+1)
  for (std::size_t k = 1; k <= n + 1; ++k) {
    double s = h[k];
    for (std::size_t i = 1; i < k && i <= n; ++i) s += den_z[i] * h[k - i];
    num_z[k] = s;
  }
  // Direct feedthrough of the delayed input: D u(k-d) or, with a fractional
  // delay, D u(k-d-1) at the sampling instant.
  if (dterm != 0.0) {
    const std::size_t shift = theta > 0.0 ? 1 : 0;
    for (std::size_t i = 0; i <= n; ++i) num_z[i + shift] += dterm * den_z[i];
  }
  // Clean round-off and move leading zeros into the delay.
  double scale = 0.0;
  for (double x : num_z) scale = std::max(scale, std::abs(x));
  for (double& x : num_z)
    if (std::abs(x) <= 1e-13 * scale) x = 0.0;
  std::size_t lead_zeros = 0;
  while (lead_zeros + 1 < num_z.size() && num_z[lead_zeros] == 0.0) ++lead_zeros;
  out.num.assign(num_z.begin() + static_cast<long>(lead_zeros), num_z.end());
  out.den = den_z;
  out.delay = d + static_cast<int>(lead_zeros);
  out.normalise();
  return out;
}

DiscreteFilter::DiscreteFilter(const DiscreteTf& tf) : tf_(tf) {
  tf_.normalise();
  u_hist_.assign(static_cast<std::size_t>(tf_.delay) + tf_.num.size(), 0.0);
  y_hist_.assign(tf_.den.size() - 1, 0.0);
}

double DiscreteFilter::step(double u) noexcept {
  // Shift histories (short: delay + order); newest at index 0.
  if (!u_hist_.empty()) {
    std::copy_backward(u_hist_.begin(), u_hist_.end() - 1, u_hist_.end());
    u_hist_[0] = u;
  }
  double y = 0.0;
  const std::size_t d = static_cast<std::size_t>(tf_.delay);
  for (std::size_t i = 0; i < tf_.num.size(); ++i) y += tf_.num[i] * u_hist_[d + i];
  for (std::size_t i = 1; i < tf_.den.size(); ++i) y -= tf_.den[i] * y_hist_[i - 1];
  if (!y_hist_.empty()) {
    std::copy_backward(y_hist_.begin(), y_hist_.end() - 1, y_hist_.end());
    y_hist_[0] = y;
  }
  return y;
}

void DiscreteFilter::reset(double u_rest) noexcept {
  std::fill(u_hist_.begin(), u_hist_.end(), u_rest);
  const double g = tf_.dc_gain();
  const double y_rest = std::isfinite(g) ? g * u_rest : 0.0;
  std::fill(y_hist_.begin(), y_hist_.end(), y_rest);
}

}  // namespace mpm
