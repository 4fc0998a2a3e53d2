// OVERVIEW
// Square-root information recursive least squares with exponential
// forgetting: the textbook form, and the reference the monitor's factors
// are tested against (UdRls keeps the same factor without square roots,
// BiermanRls its inverse in covariance form).
//
// Keeps the upper-triangular factor R of the weighted augmented data matrix
// [X y] (R^T R = sum_k lambda^(n-k) [x_k; y_k][x_k; y_k]^T + prior), updated
// per sample by absorbing the new row with Givens rotations, the forgetting
// sqrt(lambda) folded into each rotation: O(p^2), no allocation, and unlike
// the covariance (P-form) recursion it stays equal to a batch QR fit after
// millions of samples.
//
// Because the target is the last column of R, the residual sum of squares of
// every model made of the *first k* regressors is a partial sum of squares of
// that column: nested models are free. A model without an inner block of
// regressors is recovered by re-triangularising the trailing part of R in
// scratch storage (rss_without, O(p^2 count)); UdRls shares that step.
//
// Poor excitation: the prior of `regularization` per regressor is kept alive
// as in the core's factors (core/rls_common.hpp, KeptAlivePrior).
//
// Not used by the product: the monitor keeps the same factor without square
// roots (UdRls). It lives beside the batch QR oracle as the textbook form
// the core's factors are checked against (and for the benchmarks' baseline).
#pragma once

#include <cstddef>
#include <cstdint>

#include <Eigen/Dense>

#include "core/rls_common.hpp"

namespace mpm {

class SqrtRls {
 public:
  using Matrix = RlsMatrix;

  SqrtRls() = default;
  // n_regressors >= 1, forgetting in (0, 1], regularization > 0.
  SqrtRls(std::size_t n_regressors, double forgetting, double regularization = 1e-9);

  // Real-time safe. x: n_regressors values, y: target.
  void update(const double* x, double y) noexcept;
  // Absorbs one row with weight 1 and no forgetting. Real-time safe.
  void add_row(const double* x, double y) noexcept;

  std::size_t n_regressors() const noexcept { return p_; }
  // Weighted residual sum of squares of the model of the first k regressors
  // (k = 0: sum of squares of y; k = n_regressors(): the full model).
  // Real-time safe; suffix sums computed once per change.
  double rss_prefix(std::size_t k) const noexcept;
  double rss() const noexcept {
    const double v = r_(static_cast<Eigen::Index>(p_), static_cast<Eigen::Index>(p_));
    return v * v;
  }
  // Weighted RSS of the model that leaves out regressors [first, first+count).
  // `scratch` must be at least (p+1) x (p+1); it is overwritten. Real-time safe.
  double rss_without(std::size_t first, std::size_t count, Matrix& scratch) const noexcept;
  // Coefficients of the model of the first k regressors (back substitution).
  // out.size() >= k; writes out[0..k). Real-time safe.
  void solve_prefix(std::size_t k, Eigen::Ref<Eigen::VectorXd> out) const noexcept;
  // The factor, (p+1) x (p+1) upper triangular; last column = target.
  Eigen::Ref<const Matrix> factor() const noexcept { return r_.leftCols(static_cast<Eigen::Index>(p_ + 1)); }
  // Back to the prior.
  void reset() noexcept;

 private:
  std::size_t p_ = 0;
  double lambda_ = 1.0;
  double sqrt_lambda_ = 1.0;
  double delta_ = 1e-9;
  KeptAlivePrior prior_;
  Matrix r_;                // (p+1) x padded(p+1), rows padded with zeros to whole lanes (givens.hpp)
  Eigen::VectorXd work_;    // row being absorbed, p+1 values and padding
  std::uint64_t changes_ = 0;      // bumped by every absorbed row
  mutable std::uint64_t rss_stamp_ = ~std::uint64_t{0};
  mutable Eigen::VectorXd rss_tail_;  // rss_prefix(k) for k = 0..p when rss_stamp_ == changes_

  // Absorbs work_ into r_ (rows >= first), pivot rows scaled by `scale`
  // first (scale != 1 needs first == 0).
  void absorb(std::size_t first, double scale) noexcept;
  void refresh_prior() noexcept;  // the kept-alive prior row, when due
};

}  // namespace mpm
