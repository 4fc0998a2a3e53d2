#include "support/sqrt_rls.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/givens.hpp"

namespace mpm {

SqrtRls::SqrtRls(std::size_t n_regressors, double forgetting, double regularization)
    : p_(n_regressors), lambda_(forgetting), sqrt_lambda_(std::sqrt(forgetting)), delta_(regularization) {
  if (n_regressors == 0) throw std::invalid_argument("SqrtRls: need at least one regressor");
  if (!(forgetting > 0.0 && forgetting <= 1.0)) throw std::invalid_argument("SqrtRls: forgetting must be in (0, 1]");
  if (!(regularization > 0.0)) throw std::invalid_argument("SqrtRls: regularization must be > 0");
  prior_ = KeptAlivePrior(p_, lambda_, delta_);
  const auto n = static_cast<Eigen::Index>(p_ + 1);
  const auto width = static_cast<Eigen::Index>(givens::padded(p_ + 1));
  r_.resize(n, width);
  work_ = Eigen::VectorXd::Zero(width);
  rss_tail_ = Eigen::VectorXd::Zero(n);
  reset();
}

void SqrtRls::reset() noexcept {
  r_.setZero();
  for (std::size_t i = 0; i < p_; ++i) r_(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(i)) = std::sqrt(delta_);
  prior_.reset();
  ++changes_;
}

void SqrtRls::absorb(std::size_t first, double scale) noexcept {
  const std::size_t n = p_ + 1;
  const std::size_t width = givens::padded(n);
  double* w = work_.data();
  ++changes_;
  for (std::size_t i = first; i < n; ++i) givens::rotate(r_.row(static_cast<Eigen::Index>(i)).data(), w, i, width, scale);
}

void SqrtRls::update(const double* x, double y) noexcept {
  std::copy(x, x + p_, work_.data());
  work_[static_cast<Eigen::Index>(p_)] = y;
  absorb(0, sqrt_lambda_);  // forgetting folded into the rotations
  refresh_prior();
}

void SqrtRls::add_row(const double* x, double y) noexcept {
  std::copy(x, x + p_, work_.data());
  work_[static_cast<Eigen::Index>(p_)] = y;
  absorb(0, 1.0);
}

void SqrtRls::refresh_prior() noexcept {
  if (const auto row = prior_.due(work_.data(), p_ + 1)) absorb(*row, 1.0);
}

double SqrtRls::rss_prefix(std::size_t k) const noexcept {
  if (rss_stamp_ != changes_) {
    // Suffix sums of the squared target column: RSS of the first k
    // regressors is what rows k..p leave of y.
    const auto last = static_cast<Eigen::Index>(p_);
    double s = 0.0;
    for (std::size_t i = p_ + 1; i-- > 0;) {
      const double v = r_(static_cast<Eigen::Index>(i), last);
      s += v * v;
      rss_tail_[static_cast<Eigen::Index>(i)] = s;
    }
    rss_stamp_ = changes_;
  }
  return rss_tail_[static_cast<Eigen::Index>(k)];
}

double SqrtRls::rss_without(std::size_t first, std::size_t count, Matrix& scratch) const noexcept {
  if (count == 0) return rss();
  if (first + count >= p_ + 1) return rss_prefix(first);  // dropping a trailing block
  // Rows [first, p] and the columns after the block, target last: upper
  // trapezoidal with `count` extra subdiagonals. Re-triangularised by one
  // Householder reflection per column (one square root per column instead of
  // `count` dependent Givens rotations).
  const std::size_t rows = p_ + 1 - first;
  const std::size_t cols = p_ + 1 - first - count;
  for (std::size_t r = 0; r < rows; ++r) {
    double* dst = scratch.row(static_cast<Eigen::Index>(r)).data();
    const double* src = r_.row(static_cast<Eigen::Index>(first + r)).data() + first + count;
    for (std::size_t c = 0; c < cols; ++c) dst[c] = src[c];
  }
  return mpm::retriangularised_rss(scratch, rows, cols, count);
}

void SqrtRls::solve_prefix(std::size_t k, Eigen::Ref<Eigen::VectorXd> out) const noexcept {
  // Back substitution R[0:k, 0:k] beta = R[0:k, p], column by column: the
  // dependency chain per coefficient is one product and one update (the
  // reciprocal of the diagonal does not wait for it), not a whole dot product.
  const auto last = static_cast<Eigen::Index>(p_);
  double* beta = out.data();
  for (std::size_t i = 0; i < k; ++i) beta[i] = r_(static_cast<Eigen::Index>(i), last);
  for (std::size_t i = k; i-- > 0;) {
    const auto ii = static_cast<Eigen::Index>(i);
    const double b = beta[i] * (1.0 / r_(ii, ii));
    beta[i] = b;
    for (std::size_t r = 0; r < i; ++r) beta[r] -= r_(static_cast<Eigen::Index>(r), ii) * b;
  }
}

}  // namespace mpm
