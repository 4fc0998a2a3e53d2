// OVERVIEW
// Square-root information recursive least squares with exponential forgetting.
//
// Keeps the upper-triangular factor R of the weighted augmented data matrix
// [X y] (R^T R = sum_k lambda^(n-k) [x_k; y_k][x_k; y_k]^T + prior), updated
// per sample by scaling with sqrt(lambda) and absorbing the new row with
// Givens rotations: O(p^2), no allocation, and unlike the covariance (P-form)
// recursion it stays equal to a batch QR fit after millions of samples.
//
// Because the target is the last column of R, the residual sum of squares of
// every model made of the *first k* regressors is a partial sum of squares of
// that column: nested models (AR-only inside AR + inputs) are free. A model
// without an inner block of regressors is recovered by re-triangularising the
// trailing part of R in scratch storage (rss_without).
//
// Poor excitation: with lambda < 1 the information in unexcited directions
// decays and the covariance would blow up. A prior of weight `regularization`
// per regressor is kept alive by re-adding, round robin, one scaled unit row
// per sample (the amortised equivalent of adding (1 - lambda) * delta * I
// every sample), so R^T R >= ~delta I at all times and the covariance stays
// bounded. With lambda = 1 only the initial prior is added, so the fit equals
// batch least squares with a ridge of `regularization` (negligible at 1e-9).
#pragma once

#include <cstddef>

#include <Eigen/Dense>

namespace mpm {

class SqrtRls {
 public:
  // Row-major: a Givens rotation walks two rows, contiguous in memory.
  using Matrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

  SqrtRls() = default;
  // n_regressors >= 1, forgetting in (0, 1], regularization > 0.
  SqrtRls(std::size_t n_regressors, double forgetting, double regularization = 1e-9);

  // Real-time safe. x: n_regressors values, y: target.
  void update(const double* x, double y) noexcept;

  std::size_t n_regressors() const noexcept { return p_; }
  // Weighted residual sum of squares of the model of the first k regressors
  // (k = 0: sum of squares of y; k = n_regressors(): the full model).
  double rss_prefix(std::size_t k) const noexcept;
  double rss() const noexcept { return rss_prefix(p_); }
  // Weighted RSS of the model that leaves out regressors [first, first+count).
  // `scratch` must be at least (p+1) x (p+1); it is overwritten. Real-time safe.
  double rss_without(std::size_t first, std::size_t count, Matrix& scratch) const noexcept;
  // Coefficients of the model of the first k regressors (back substitution).
  // out.size() >= k; writes out[0..k). Real-time safe.
  void solve_prefix(std::size_t k, Eigen::Ref<Eigen::VectorXd> out) const noexcept;
  // The factor, (p+1) x (p+1) upper triangular; last column = target.
  const Matrix& factor() const noexcept { return r_; }
  // Back to the prior.
  void reset() noexcept;

 private:
  std::size_t p_ = 0;
  double lambda_ = 1.0;
  double sqrt_lambda_ = 1.0;
  double delta_ = 1e-9;
  std::size_t next_prior_row_ = 0;
  Matrix r_;                // (p+1) x (p+1)
  Eigen::VectorXd work_;    // row being absorbed, size p+1
  void absorb(std::size_t first_nonzero) noexcept;  // absorbs work_ into r_
};

}  // namespace mpm
