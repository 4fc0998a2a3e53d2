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
// Poor excitation: with lambda < 1 the information in unexcited directions
// decays and the covariance would blow up. A prior of weight `regularization`
// per regressor is kept alive by re-adding, round robin, one scaled unit row
// every K samples (the amortised equivalent of adding (1 - lambda) * delta * I
// every sample), so R^T R >= ~delta I / 4 at all times and the covariance
// stays bounded. K <= 64 is chosen so that a direction waits at most p * K
// samples, during which its prior decays by no more than a factor of 4. With
// lambda = 1 only the initial prior is added, so the fit equals batch least
// squares with a ridge of `regularization` (negligible at 1e-9).
#pragma once

#include <cstddef>
#include <cstdint>

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
  // What rss_without does once it has copied the trapezoid: rows x cols of
  // scratch, upper triangular but for `count` subdiagonals, target column
  // last; returns the RSS left after re-triangularising it (overwritten).
  static double retriangularised_rss(Matrix& scratch, std::size_t rows, std::size_t cols, std::size_t count) noexcept;
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
  int prior_period_ = 1;        // K: samples between kept-alive prior rows
  int since_prior_ = 0;
  double prior_weight_ = 0.0;   // sqrt(p K (1 - lambda) delta)
  std::size_t next_prior_row_ = 0;
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
