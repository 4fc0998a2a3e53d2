#include "core/diagnosis_signal.hpp"

#include <cmath>
#include <complex>
#include <utility>

namespace mpm::diagnosis {

Vec simulate(const DiscreteTf& tf, const Vec& x) {
  // The same arithmetic as DiscreteFilter::step from rest, term by term in
  // the same order (so bit for bit the same output), but over the whole
  // record at once: the numerator's terms as vector passes over cache-sized
  // chunks, then the denominator's recursion in one scalar loop. step()
  // shifts its histories every sample, which costs O(delay) per sample; here
  // a delay costs nothing.
  DiscreteTf t = tf;
  t.normalise();
  const Index n = x.size();
  Vec y(n);
  const auto delay = static_cast<Index>(t.delay);
  const double* xs = x.data();
  double* ys = y.data();
  constexpr Index kChunk = 2048;
  for (Index c0 = 0; c0 < n; c0 += kChunk) {
    const Index c1 = std::min(n, c0 + kChunk);
    // step() starts each sample's sum at 0.0 and adds num[0] u(k - delay)
    // first: so does this (0.0 + v, as there, not v: the same zero's sign).
    const double b0 = t.num[0];
    for (Index k = c0; k < std::min(c1, delay); ++k) ys[k] = 0.0;
    for (Index k = std::max(c0, delay); k < c1; ++k) ys[k] = 0.0 + b0 * xs[k - delay];
    for (std::size_t i = 1; i < t.num.size(); ++i) {
      const Index lag = delay + static_cast<Index>(i);
      const double b = t.num[i];
      for (Index k = std::max(c0, lag); k < c1; ++k) ys[k] += b * xs[k - lag];
    }
  }
  const auto na = static_cast<Index>(t.den.size()) - 1;
  // The recursion is latency-bound: the last outputs are carried in
  // registers, not reloaded from the stores just made.
  if (na == 1 && n > 0) {
    const double a1 = t.den[1];
    double y1 = ys[0];
    for (Index k = 1; k < n; ++k) ys[k] = y1 = ys[k] - a1 * y1;
  } else if (na == 2 && n > 0) {
    const double a1 = t.den[1], a2 = t.den[2];
    double y2 = 0.0, y1 = ys[0];
    if (n > 1) ys[1] = y1 = ys[1] - a1 * (y2 = y1);
    for (Index k = 2; k < n; ++k) {
      const double v = ys[k] - a1 * y1 - a2 * y2;
      y2 = y1;
      ys[k] = y1 = v;
    }
  } else if (na > 2) {
    for (Index k = 0; k < n; ++k) {
      double v = ys[k];
      const Index last = std::min(na, k);
      for (Index i = 1; i <= last; ++i) v -= t.den[static_cast<std::size_t>(i)] * ys[k - i];
      ys[k] = v;
    }
  }
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
  std::vector<double> a(static_cast<std::size_t>(order) + 1, 0.0);
  a[0] = 1.0;
  // The rows: samples of the mask from `order` on, as runs of consecutive
  // samples, so that every sum below is a vector pass over a run.
  std::vector<std::pair<Index, Index>> runs;
  Index rows = 0;
  for (Index k = order; k < x.size(); ++k) {
    if (!mask[static_cast<std::size_t>(k)]) continue;
    if (runs.empty() || runs.back().second != k) runs.push_back({k, k});
    runs.back().second = k + 1;
    ++rows;
  }
  if (rows < 4 * (order + 1)) return a;
  // Normal equations on centred columns (the intercept), as least_squares_at
  // solves them: the order is 1-3 and the lags of a whitened residual are
  // well conditioned, so they lose nothing to a QR of the N x (order + 1)
  // matrix and need no copy of it. Column l is x lagged by l (0: the target).
  const auto column = [&](int l, Index first, Index end) { return x.segment(first - l, end - first); };
  Vec mean = Vec::Zero(order + 1);
  for (const auto& [first, end] : runs)
    for (int l = 0; l <= order; ++l) mean(l) += column(l, first, end).sum();
  mean /= static_cast<double>(rows);
  Eigen::MatrixXd gram = Eigen::MatrixXd::Zero(order + 1, order + 1);
  for (const auto& [first, end] : runs)
    for (int l = 0; l <= order; ++l)
      for (int m = 0; m <= l; ++m)
        gram(l, m) += (column(l, first, end).array() - mean(l)).matrix().dot(
            (column(m, first, end).array() - mean(m)).matrix());
  const Eigen::MatrixXd lags = gram.bottomRightCorner(order, order).selfadjointView<Eigen::Lower>();
  const Vec beta = lags.ldlt().solve(gram.col(0).tail(order));
  for (int l = 1; l <= order; ++l) a[static_cast<std::size_t>(l)] = -beta(l - 1);
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

namespace {

// Maximal runs [first, end) of nonzero entries of mask from `begin` on.
std::vector<std::pair<Index, Index>> runs_of(const std::vector<char>& mask, Index begin) {
  std::vector<std::pair<Index, Index>> runs;
  const auto n = static_cast<Index>(mask.size());
  for (Index k = std::max<Index>(begin, 0); k < n; ++k) {
    if (!mask[static_cast<std::size_t>(k)]) continue;
    if (runs.empty() || runs.back().second != k) runs.push_back({k, k});
    runs.back().second = k + 1;
  }
  return runs;
}

// Rows of the normal equations are summed over blocks of this many samples
// (one block of every column stays in L1).
constexpr Index kBlock = 256;

// LinearFit::cv_var of the fit `fitted` (its theta and hold_var): per fold,
// the Gram matrix of [X, y] centred at the fit part's means (mx, my) and its
// column sums, so that the fit on the other folds is their sums, re-centred
// at their own mean; then each fold's errors under that fit. The held-out
// fold's other folds are the fit part: its variance is fitted.hold_var.
double cross_fitted_variance(const Vec& target, const std::vector<const Vec*>& regressors, const Segments& seg,
                             const Vec& mx, double my, LinearFit& fitted) {
  const auto p = static_cast<Index>(regressors.size());
  const auto x = [&](Index i) -> const Vec& { return *regressors[static_cast<std::size_t>(i)]; };
  const std::size_t folds = seg.fold_runs.size();
  std::vector<Eigen::MatrixXd> gram(folds, Eigen::MatrixXd::Zero(p + 1, p + 1));
  std::vector<Vec> sums(folds, Vec::Zero(p + 1));
  std::vector<Index> count(folds, 0);
  std::vector<bool> held(folds, false);
  Eigen::MatrixXd B(kBlock, p + 1);
  for (std::size_t f = 0; f < folds; ++f)
    for (const auto& [first, end] : seg.fold_runs[f]) {
      held[f] = held[f] || seg.hold[static_cast<std::size_t>(first)];
      count[f] += end - first;
      for (Index k = first; k < end; k += kBlock) {
        const Index m = std::min(kBlock, end - k);
        for (Index i = 0; i < p; ++i) B.col(i).head(m) = x(i).segment(k, m).array() - mx(i);
        B.col(p).head(m) = target.segment(k, m).array() - my;
        gram[f].selfadjointView<Eigen::Lower>().rankUpdate(B.topRows(m).transpose());
        sums[f] += B.topRows(m).colwise().sum().transpose();
      }
    }
  double pooled = 0.0;
  Index judged = 0;
  fitted.fold_var = Vec::Zero(static_cast<Index>(folds));
  Eigen::ArrayXd e(kBlock);
  for (std::size_t f = 0; f < folds; ++f) {
    if (count[f] < 2) continue;
    if (held[f]) {
      fitted.fold_var(static_cast<Index>(f)) = fitted.hold_var;
      pooled += fitted.hold_var * static_cast<double>(count[f]);
      judged += count[f];
      continue;
    }
    Eigen::MatrixXd G = Eigen::MatrixXd::Zero(p + 1, p + 1);
    Vec s = Vec::Zero(p + 1);
    Index n = 0;
    for (std::size_t g = 0; g < folds; ++g)
      if (g != f) {
        G += gram[g];
        s += sums[g];
        n += count[g];
      }
    if (n < p + 2) continue;
    const Eigen::MatrixXd full = G.selfadjointView<Eigen::Lower>();
    const Eigen::MatrixXd centred = full - s * s.transpose() / static_cast<double>(n);
    Vec theta = Vec::Zero(p);
    if (p > 0) {
      theta = centred.topLeftCorner(p, p).ldlt().solve(centred.col(p).head(p));
      if (!theta.allFinite()) theta.setZero();
    }
    double h = 0.0, h2 = 0.0;
    for (const auto& [first, end] : seg.fold_runs[f])
      for (Index k = first; k < end; k += kBlock) {
        const Index m = std::min(kBlock, end - k);
        e.head(m) = target.segment(k, m).array();
        for (Index i = 0; i < p; ++i) e.head(m) -= theta(i) * x(i).segment(k, m).array();
        h += e.head(m).sum();
        h2 += e.head(m).square().sum();
      }
    const double mean = h / static_cast<double>(count[f]);
    const double spread = std::max(0.0, h2 - static_cast<double>(count[f]) * mean * mean);
    fitted.fold_var(static_cast<Index>(f)) = std::max(1e-300, spread / static_cast<double>(count[f]));
    pooled += spread;
    judged += count[f];
  }
  return judged > 1 ? std::max(1e-300, pooled / static_cast<double>(judged)) : fitted.hold_var;
}

}  // namespace

void Segments::index() {
  fit_runs = runs_of(fit, begin);
  hold_runs = runs_of(hold, begin);
  fold_runs.clear();
  for (const signed char f : fold)
    if (f >= 0 && static_cast<std::size_t>(f) >= fold_runs.size()) fold_runs.resize(static_cast<std::size_t>(f) + 1);
  std::vector<char> mask(fold.size());
  for (std::size_t f = 0; f < fold_runs.size(); ++f) {
    for (std::size_t k = 0; k < fold.size(); ++k) mask[k] = fold[k] == static_cast<signed char>(f);
    fold_runs[f] = runs_of(mask, begin);
  }
  indexed = true;
}

LinearFit least_squares(const Vec& target, const std::vector<Vec>& regressors, const Segments& seg, Part part) {
  std::vector<const Vec*> cols;
  cols.reserve(regressors.size());
  for (const Vec& x : regressors) cols.push_back(&x);
  return least_squares_at(target, cols, seg, part);
}

LinearFit least_squares_at(const Vec& target, const std::vector<const Vec*>& regressors, const Segments& seg,
                           Part part) {
  Segments local;
  if (!seg.indexed) {
    local.fit_runs = runs_of(seg.fit, seg.begin);
    local.hold_runs = runs_of(seg.hold, seg.begin);
  }
  const auto& fit_runs = seg.indexed ? seg.fit_runs : local.fit_runs;
  const auto& hold_runs = seg.indexed ? seg.hold_runs : local.hold_runs;
  const auto p = static_cast<Index>(regressors.size());
  const auto x = [&](Index i) -> const Vec& { return *regressors[static_cast<std::size_t>(i)]; };
  // Normal equations on centred data (the intercept): p is 1-7 here, and the
  // centring keeps them as well conditioned as the regressors themselves.
  Index n = 0;
  double ty = 0.0;
  Vec tx = Vec::Zero(p);
  for (const auto& [first, end] : fit_runs) {
    n += end - first;
    ty += target.segment(first, end - first).sum();
    for (Index i = 0; i < p; ++i) tx(i) += x(i).segment(first, end - first).sum();
  }
  LinearFit out;
  out.theta = Vec::Zero(p);
  out.theta_se = Vec::Zero(p);
  if (n < 2) return out;
  const double my = ty / static_cast<double>(n);
  const Vec mx = tx / static_cast<double>(n);
  if (p > 0) {
    // [X - mx, y - my] block by block: its Gram matrix holds A and b.
    Eigen::MatrixXd G = Eigen::MatrixXd::Zero(p + 1, p + 1);
    Eigen::MatrixXd B(kBlock, p + 1);
    for (const auto& [first, end] : fit_runs)
      for (Index k = first; k < end; k += kBlock) {
        const Index m = std::min(kBlock, end - k);
        for (Index i = 0; i < p; ++i) B.col(i).head(m) = x(i).segment(k, m).array() - mx(i);
        B.col(p).head(m) = target.segment(k, m).array() - my;
        G.selfadjointView<Eigen::Lower>().rankUpdate(B.topRows(m).transpose());
      }
    const Eigen::MatrixXd A = G.topLeftCorner(p, p).selfadjointView<Eigen::Lower>();
    const Vec b = G.row(p).head(p).transpose();
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(A);
    out.theta = ldlt.solve(b);
    if (!out.theta.allFinite()) out.theta.setZero();
    out.theta_se = ldlt.solve(Eigen::MatrixXd::Identity(p, p)).diagonal().cwiseMax(0.0).cwiseSqrt();
  }
  // Errors e = y - X theta over [first, first + m), into e.
  Eigen::ArrayXd e(kBlock);
  const auto errors = [&](Index first, Index m) {
    e.head(m) = target.segment(first, m).array();
    for (Index i = 0; i < p; ++i) e.head(m) -= out.theta(i) * x(i).segment(first, m).array();
  };
  double s = 0.0, s2 = 0.0;
  for (const auto& [first, end] : fit_runs)
    for (Index k = first; k < end; k += kBlock) {
      const Index m = std::min(kBlock, end - k);
      errors(k, m);
      s += e.head(m).sum();
      s2 += e.head(m).square().sum();
    }
  out.fit_var = std::max(1e-300, s2 / static_cast<double>(n) - (s / static_cast<double>(n)) * (s / static_cast<double>(n)));
  if (p > 0) out.theta_se *= std::sqrt(out.fit_var);
  if (part == Part::fit) return out;
  out.hold_error = Vec::Zero(target.size());
  double h = 0.0, h2 = 0.0;
  Index nh = 0;
  for (const auto& [first, end] : hold_runs)
    for (Index k = first; k < end; k += kBlock) {
      const Index m = std::min(kBlock, end - k);
      errors(k, m);
      out.hold_error.segment(k, m) = e.head(m).matrix();
      h += e.head(m).sum();
      h2 += e.head(m).square().sum();
      nh += m;
    }
  if (nh > 1) {
    const double mh = h / static_cast<double>(nh);
    out.hold_var = std::max(1e-300, h2 / static_cast<double>(nh) - mh * mh);
    for (const auto& [first, end] : hold_runs) out.hold_error.segment(first, end - first).array() -= mh;
  }
  out.cv_var = seg.indexed && seg.fold_runs.size() > 1 ? cross_fitted_variance(target, regressors, seg, mx, my, out)
                                                        : out.hold_var;
  return out;
}

}  // namespace mpm::diagnosis
