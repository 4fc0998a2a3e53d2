#include "core/sqrt_rls.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace mpm {
namespace {

// Rotates rows a (pivot) and b so that b[first] becomes 0; columns
// [first, end) of both rows are updated. Returns nothing; a[first] >= 0.
inline void givens(double* a, double* b, std::size_t first, std::size_t end) noexcept {
  const double x = a[first];
  const double y = b[first];
  if (y == 0.0) return;
  const double r = std::sqrt(x * x + y * y);
  const double c = x / r;
  const double s = y / r;
  a[first] = r;
  b[first] = 0.0;
  for (std::size_t j = first + 1; j < end; ++j) {
    const double aj = a[j];
    const double bj = b[j];
    a[j] = c * aj + s * bj;
    b[j] = c * bj - s * aj;
  }
}

}  // namespace

SqrtRls::SqrtRls(std::size_t n_regressors, double forgetting, double regularization)
    : p_(n_regressors), lambda_(forgetting), sqrt_lambda_(std::sqrt(forgetting)), delta_(regularization) {
  if (n_regressors == 0) throw std::invalid_argument("SqrtRls: need at least one regressor");
  if (!(forgetting > 0.0 && forgetting <= 1.0)) throw std::invalid_argument("SqrtRls: forgetting must be in (0, 1]");
  if (!(regularization > 0.0)) throw std::invalid_argument("SqrtRls: regularization must be > 0");
  const auto n = static_cast<Eigen::Index>(p_ + 1);
  r_.resize(n, n);
  work_.resize(n);
  reset();
}

void SqrtRls::reset() noexcept {
  r_.setZero();
  for (std::size_t i = 0; i < p_; ++i) r_(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(i)) = std::sqrt(delta_);
  next_prior_row_ = 0;
}

void SqrtRls::absorb(std::size_t first_nonzero) noexcept {
  const std::size_t n = p_ + 1;
  double* w = work_.data();
  for (std::size_t i = first_nonzero; i < n; ++i) {
    if (w[i] == 0.0) continue;
    givens(r_.row(static_cast<Eigen::Index>(i)).data(), w, i, n);
  }
}

void SqrtRls::update(const double* x, double y) noexcept {
  const std::size_t n = p_ + 1;
  if (lambda_ < 1.0) {
    for (std::size_t i = 0; i < n; ++i) {
      double* row = r_.row(static_cast<Eigen::Index>(i)).data();
      for (std::size_t j = i; j < n; ++j) row[j] *= sqrt_lambda_;
    }
    // Keep the prior alive: one unit row per sample, round robin, weighted so
    // that p of them add (1 - lambda) * delta * p per direction (see header).
    work_.setZero();
    const std::size_t i = next_prior_row_;
    work_[static_cast<Eigen::Index>(i)] = std::sqrt(static_cast<double>(p_) * (1.0 - lambda_) * delta_);
    absorb(i);
    next_prior_row_ = (next_prior_row_ + 1) % p_;
  }
  for (std::size_t j = 0; j < p_; ++j) work_[static_cast<Eigen::Index>(j)] = x[j];
  work_[static_cast<Eigen::Index>(p_)] = y;
  absorb(0);
}

double SqrtRls::rss_prefix(std::size_t k) const noexcept {
  double s = 0.0;
  const auto last = static_cast<Eigen::Index>(p_);
  for (std::size_t i = k; i <= p_; ++i) {
    const double v = r_(static_cast<Eigen::Index>(i), last);
    s += v * v;
  }
  return s;
}

double SqrtRls::rss_without(std::size_t first, std::size_t count, Matrix& scratch) const noexcept {
  if (count == 0) return rss();
  if (first + count >= p_ + 1) return rss_prefix(first);  // dropping a trailing block
  // Rows [first, p] and the columns after the block, target last: upper
  // trapezoidal with `count` extra subdiagonals; re-triangularise by Givens.
  const std::size_t rows = p_ + 1 - first;
  const std::size_t cols = p_ + 1 - first - count;
  for (std::size_t r = 0; r < rows; ++r) {
    double* dst = scratch.row(static_cast<Eigen::Index>(r)).data();
    const double* src = r_.row(static_cast<Eigen::Index>(first + r)).data() + first + count;
    for (std::size_t c = 0; c < cols; ++c) dst[c] = src[c];
  }
  for (std::size_t c = 0; c + 1 < cols; ++c) {
    double* pivot = scratch.row(static_cast<Eigen::Index>(c)).data();
    const std::size_t last_row = std::min(rows - 1, c + count);
    for (std::size_t r = c + 1; r <= last_row; ++r)
      givens(pivot, scratch.row(static_cast<Eigen::Index>(r)).data(), c, cols);
  }
  double s = 0.0;
  for (std::size_t r = cols - 1; r < rows; ++r) {
    const double v = scratch(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(cols - 1));
    s += v * v;
  }
  return s;
}

void SqrtRls::solve_prefix(std::size_t k, Eigen::Ref<Eigen::VectorXd> out) const noexcept {
  // Back substitution R[0:k, 0:k] beta = R[0:k, p].
  const auto last = static_cast<Eigen::Index>(p_);
  for (std::size_t ii = k; ii-- > 0;) {
    const auto i = static_cast<Eigen::Index>(ii);
    double s = r_(i, last);
    for (Eigen::Index j = i + 1; j < static_cast<Eigen::Index>(k); ++j) s -= r_(i, j) * out[j];
    out[i] = s / r_(i, i);
  }
}

}  // namespace mpm
