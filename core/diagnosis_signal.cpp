#include "core/diagnosis_signal.hpp"

#include <cmath>
#include <complex>

namespace mpm::diagnosis {

Vec simulate(const DiscreteTf& tf, const Vec& x) {
  DiscreteFilter f(tf);
  f.reset(0.0);
  Vec y(x.size());
  for (Index k = 0; k < x.size(); ++k) y(k) = f.step(x(k));
  return y;
}

Vec shifted(const Vec& x, int lag) {
  Vec y = Vec::Zero(x.size());
  const Index n = x.size();
  for (Index k = 0; k < n; ++k) {
    const Index src = k - lag;
    if (src >= 0 && src < n) y(k) = x(src);
  }
  return y;
}

Vec backlash(const Vec& u, double width) {
  Vec y(u.size());
  if (u.size() == 0) return y;
  const double half = 0.5 * width;
  double out = u(0);
  for (Index k = 0; k < u.size(); ++k) {
    if (u(k) > out + half) out = u(k) - half;
    if (u(k) < out - half) out = u(k) + half;
    y(k) = out;
  }
  return y;
}

Vec clipped(const Vec& u, double lo, double hi) { return u.cwiseMax(lo).cwiseMin(hi); }

std::vector<double> poly_mul(const std::vector<double>& a, const std::vector<double>& b) {
  std::vector<double> c(a.size() + b.size() - 1, 0.0);
  for (std::size_t i = 0; i < a.size(); ++i)
    for (std::size_t j = 0; j < b.size(); ++j) c[i + j] += a[i] * b[j];
  return c;
}

DiscreteTf series(const DiscreteTf& a, const DiscreteTf& b) {
  DiscreteTf c;
  c.num = poly_mul(a.num, b.num);
  c.den = poly_mul(a.den, b.den);
  c.delay = a.delay + b.delay;
  return c;
}

DiscreteTf unit_lag(double pole) {
  DiscreteTf t;
  t.num = {1.0 - pole};
  t.den = {1.0, -pole};
  return t;
}

double slowest_pole(const DiscreteTf& tf) {
  const auto n = static_cast<Index>(tf.den.size()) - 1;
  if (n < 1) return 0.0;
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(n, n);
  for (Index i = 0; i < n; ++i) c(0, i) = -tf.den[static_cast<std::size_t>(i + 1)] / tf.den[0];
  for (Index i = 1; i < n; ++i) c(i, i - 1) = 1.0;
  const Eigen::VectorXcd roots = c.eigenvalues();
  double best = 0.0;
  for (Index i = 0; i < n; ++i) {
    const std::complex<double> r = roots(i);
    if (std::abs(r.imag()) < 1e-9 && r.real() < 1.0 - 1e-9 && std::abs(r.real()) > std::abs(best)) best = r.real();
  }
  return best;
}

std::vector<double> deflate(const std::vector<double>& den, double p) {
  // Synthetic division by (1 - p q^-1): q_k = den_k + p q_{k-1}.
  std::vector<double> q(den.size() > 1 ? den.size() - 1 : 1, 0.0);
  double prev = 0.0;
  for (std::size_t k = 0; k < q.size(); ++k) {
    q[k] = den[k] + p * prev;
    prev = q[k];
  }
  return q;
}

std::vector<double> fit_ar(const Vec& x, const std::vector<char>& mask, int order) {
  std::vector<Index> rows;
  for (Index k = order; k < x.size(); ++k)
    if (mask[static_cast<std::size_t>(k)]) rows.push_back(k);
  std::vector<double> a(static_cast<std::size_t>(order) + 1, 0.0);
  a[0] = 1.0;
  if (static_cast<Index>(rows.size()) < 4 * (order + 1)) return a;
  Eigen::MatrixXd X(static_cast<Index>(rows.size()), order + 1);
  Vec y(static_cast<Index>(rows.size()));
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const auto i = static_cast<Index>(r);
    X(i, 0) = 1.0;
    for (int l = 1; l <= order; ++l) X(i, l) = x(rows[r] - l);
    y(i) = x(rows[r]);
  }
  const Vec beta = X.colPivHouseholderQr().solve(y);
  for (int l = 1; l <= order; ++l) a[static_cast<std::size_t>(l)] = -beta(l);
  return a;
}

double variance(const Vec& x, const std::vector<char>& mask) {
  double s = 0.0, s2 = 0.0;
  long n = 0;
  for (Index k = 0; k < x.size(); ++k)
    if (mask[static_cast<std::size_t>(k)]) {
      s += x(k);
      s2 += x(k) * x(k);
      ++n;
    }
  if (n < 2) return 0.0;
  const double m = s / static_cast<double>(n);
  return std::max(0.0, s2 / static_cast<double>(n) - m * m);
}

LinearFit least_squares(const Vec& target, const std::vector<Vec>& regressors, const Segments& seg) {
  const std::vector<char>& fit = seg.fit;
  const std::vector<char>& hold = seg.hold;
  const auto p = static_cast<Index>(regressors.size());
  // Normal equations on centred data (the intercept): p is 1-3 here.
  Index n = 0;
  double ty = 0.0;
  Vec tx = Vec::Zero(p);
  for (Index k = seg.begin; k < target.size(); ++k) {
    if (!fit[static_cast<std::size_t>(k)]) continue;
    ++n;
    ty += target(k);
    for (Index i = 0; i < p; ++i) tx(i) += regressors[static_cast<std::size_t>(i)](k);
  }
  LinearFit out;
  out.theta = Vec::Zero(p);
  out.theta_se = Vec::Zero(p);
  if (n < 2) return out;
  const double my = ty / static_cast<double>(n);
  const Vec mx = tx / static_cast<double>(n);
  if (p > 0) {
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(p, p);
    Vec b = Vec::Zero(p);
    Vec row(p);
    for (Index k = seg.begin; k < target.size(); ++k) {
      if (!fit[static_cast<std::size_t>(k)]) continue;
      for (Index i = 0; i < p; ++i) row(i) = regressors[static_cast<std::size_t>(i)](k) - mx(i);
      A.selfadjointView<Eigen::Lower>().rankUpdate(row);
      b += row * (target(k) - my);
    }
    A = A.selfadjointView<Eigen::Lower>();
    out.theta = A.ldlt().solve(b);
    if (!out.theta.allFinite()) out.theta.setZero();
    out.theta_se = A.ldlt().solve(Eigen::MatrixXd::Identity(p, p)).diagonal().cwiseMax(0.0).cwiseSqrt();
  }
  auto error = [&](Index k) {
    double e = target(k);
    for (Index i = 0; i < p; ++i) e -= out.theta(i) * regressors[static_cast<std::size_t>(i)](k);
    return e;
  };
  double s = 0.0, s2 = 0.0;
  for (Index k = seg.begin; k < target.size(); ++k)
    if (fit[static_cast<std::size_t>(k)]) {
      const double e = error(k);
      s += e;
      s2 += e * e;
    }
  out.fit_var = std::max(1e-300, s2 / static_cast<double>(n) - (s / static_cast<double>(n)) * (s / static_cast<double>(n)));
  if (p > 0) out.theta_se *= std::sqrt(out.fit_var);
  out.hold_error = Vec::Zero(target.size());
  double h = 0.0, h2 = 0.0;
  Index nh = 0;
  for (Index k = seg.begin; k < target.size(); ++k)
    if (hold[static_cast<std::size_t>(k)]) {
      const double e = error(k);
      out.hold_error(k) = e;
      h += e;
      h2 += e * e;
      ++nh;
    }
  if (nh > 1) {
    const double m = h / static_cast<double>(nh);
    out.hold_var = std::max(1e-300, h2 / static_cast<double>(nh) - m * m);
    for (Index k = seg.begin; k < target.size(); ++k)
      if (hold[static_cast<std::size_t>(k)]) out.hold_error(k) -= m;
  }
  return out;
}

}  // namespace mpm::diagnosis
