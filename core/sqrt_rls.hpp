// OVERVIEW
// Square-root information recursive least squares with exponential forgetting.
//
// Keeps the upper-triangular factor R of the weighted augmented data matrix
// [X y] (R^T R = sum_k lambda^(n-k) [x_k; y_k][x_k; y_k]^T + prior), updated
// per sample by absorbing the new row with Givens rotations, the forgetting
// sqrt(lambda) folded into each rotation (no separate pass over R): O(p^2),
// no allocation, and unlike the covariance (P-form) recursion it stays equal
// to a batch QR fit after millions of samples.
//
// Because the target is the last column of R, the residual sum of squares of
// every model made of the *first k* regressors is a partial sum of squares of
// that column: nested models (AR-only inside AR + inputs) are free. A model
// without an inner block of regressors is recovered either by
// re-triangularising the trailing part of R in scratch storage (rss_without,
// O(p^2 count), no extra state), or, when the inverse factor is tracked, by
// the Wald identity (rss_without_wald, O(p count^2)):
//   RSS without block b = RSS + beta_b^T [(R^T R)^-1]_bb^-1 beta_b.
// Tracking the inverse (track_inverse = true) carries L = R^-T (regressor
// part, lower triangular) through the same rotations (inverse QR-RLS: if
// Q^T [sqrt(lambda) R; x^T] = [R'; 0] then Q^T [L / sqrt(lambda); 0] =
// [R'^-T; *]); it doubles the update's cost and pays off when many blocks
// are tested.
//
// Poor excitation: with lambda < 1 the information in unexcited directions
// decays and the covariance would blow up. A prior of weight `regularization`
// per regressor is kept alive by re-adding, round robin, one scaled unit row
// every K samples (the amortised equivalent of adding (1 - lambda) * delta * I
// every sample), so R^T R >= ~delta I / 4 at all times and the covariance
// stays bounded. K <= 10 is chosen so that a direction waits at most p * K
// samples, during which its prior decays by no more than a factor of 4. With
// lambda = 1 only the initial prior is added, so the fit equals batch least
// squares with a ridge of `regularization` (negligible at 1e-9).
#pragma once

#include <algorithm>
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
  // track_inverse: also carry R^-T for rss_without_wald.
  // wald_block > 0 (needs track_inverse, n_regressors a multiple of it):
  // also track the diagonal blocks of (R^T R)^-1 for regressor blocks
  // [k wald_block, (k + 1) wald_block), so rss_without_wald of such a block
  // costs O(wald_block^3) instead of O(p wald_block^2) (see
  // downdate_block_covariances in the .cpp).
  SqrtRls(std::size_t n_regressors, double forgetting, double regularization = 1e-9,
          bool track_inverse = false, std::size_t wald_block = 0);

  // Real-time safe. x: n_regressors values, y: target.
  void update(const double* x, double y) noexcept;
  // Absorbs one row with weight 1 and no forgetting (a prior row, or the
  // part of one that a shared factor passes on). Real-time safe.
  void add_row(const double* x, double y) noexcept;
  // The same as update() in two steps, for updating independent models
  // together: write x then y into staged_row() (n_regressors + 1 values) of
  // each model, then update_staged() interleaves their rotations, so the
  // latencies of their square roots and divisions overlap. Each model ends
  // exactly as if updated alone. Real-time safe.
  double* staged_row() noexcept { return work_.data(); }
  static void update_staged(SqrtRls* const* models, std::size_t count) noexcept;

  std::size_t n_regressors() const noexcept { return p_; }
  // Weighted residual sum of squares of the model of the first k regressors
  // (k = 0: sum of squares of y; k = n_regressors(): the full model).
  // Real-time safe; the first call after a change sums the target column
  // once for every k (the monitor asks for several k per sample).
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
  // g^T S^-1 g from scratch (S lower triangle in rows [0, count), g in row
  // count); -1 if S is not positive definite. Overwrites scratch.
  static double wald_quadratic(Matrix& scratch, std::size_t count) noexcept;
  // The same by the Wald identity from the tracked inverse factor (requires
  // tracks_inverse(); otherwise falls back to rss_without). Same scratch.
  double rss_without_wald(std::size_t first, std::size_t count, Matrix& scratch) const noexcept;
  bool tracks_inverse() const noexcept { return track_inverse_; }
  // Coefficients of the model of the first k regressors (back substitution).
  // out.size() >= k; writes out[0..k). Real-time safe.
  void solve_prefix(std::size_t k, Eigen::Ref<Eigen::VectorXd> out) const noexcept;
  // The same into `out` with room for padded(k) values (givens.hpp), the
  // ones past k left zero: the form the monitor's per-sample solves use.
  void solve_prefix_padded(std::size_t k, double* out) const noexcept;
  // The factor, (p+1) x (p+1) upper triangular; last column = target.
  Eigen::Ref<const Matrix> factor() const noexcept { return r_.leftCols(static_cast<Eigen::Index>(p_ + 1)); }
  // The tracked R^-T of the regressor part, p x p lower triangular (empty
  // unless tracks_inverse()).
  Eigen::Ref<const Matrix> inverse_factor() const noexcept {
    return linv_.leftCols(std::min(linv_.cols(), static_cast<Eigen::Index>(p_)));
  }
  // Back to the prior.
  void reset() noexcept;

 private:
  std::size_t p_ = 0;
  double lambda_ = 1.0;
  double sqrt_lambda_ = 1.0;
  double inv_sqrt_lambda_ = 1.0;
  double delta_ = 1e-9;
  bool track_inverse_ = false;
  int prior_period_ = 1;        // K: samples between kept-alive prior rows
  int since_prior_ = 0;
  double prior_weight_ = 0.0;   // sqrt(p K (1 - lambda) delta)
  std::size_t next_prior_row_ = 0;
  // Rows padded with zeros to whole vector lanes (givens.hpp).
  Matrix r_;                // (p+1) x padded(p+1)
  Matrix linv_;             // p x padded(p) lower triangular R^-T, or empty
  Eigen::VectorXd work_;    // row being absorbed, p+1 values and padding
  Eigen::VectorXd work_inv_;  // its counterpart in the inverse, p and padding
  // Absorbs work_ into r_ (rows >= first), pivot rows scaled by `scale`
  // first (scale != 1 needs first == 0).
  void absorb(std::size_t first, double scale) noexcept;
  void absorb_with_inverse(std::size_t first, double scale) noexcept;
  void absorb_row(std::size_t i, double scale) noexcept;  // rotation i only
  void prefetch_row(std::size_t i) const noexcept;        // what rotation i will touch
  void refresh_prior() noexcept;  // the kept-alive prior row, when due
  // Tracked block covariances: after a row, S_b = growth S_b - v_b v_b^T;
  // one block a sample recomputed from L (at regressor b0).
  void downdate_block_covariances(double growth) noexcept;  // v = work_inv_
  void downdate_block_covariances(double growth, const double* v) noexcept;
  // update_staged of one factor of at least kPrefetchMinRegressors: the
  // sample, the prior row when due, beta and the RSS sums in one pass.
  void update_in_one_pass() noexcept;
  void resync_block_covariance(std::size_t b0) noexcept;
  // L^T z, cached until the factor changes.
  const double* coefficients_from_inverse() const noexcept;

  std::size_t wald_block_ = 0;
  Matrix block_cov_;               // p x wald_block: block b's S in rows of b
  std::size_t next_resync_ = 0;    // first regressor of the next block to resync
  std::uint64_t changes_ = 0;      // bumped by every absorbed row
  mutable std::uint64_t coef_stamp_ = ~std::uint64_t{0};
  mutable Eigen::VectorXd coef_;   // L^T z when coef_stamp_ == changes_
  mutable std::uint64_t rss_stamp_ = ~std::uint64_t{0};
  mutable Eigen::VectorXd rss_tail_;  // rss_prefix(k) for k = 0..p when rss_stamp_ == changes_
  // update_in_one_pass only (large factors): the prior row absorbed in the
  // same pass as the sample, its inverse counterpart, the target column.
  // The column itself, not its squares: summed afterwards the same way as
  // rss_prefix sums it (s += v * v, which the compiler may fuse), the RSS
  // values are bit for bit those of the lockstep path (tested).
  Eigen::VectorXd prior_work_;
  Eigen::VectorXd prior_work_inv_;
  Eigen::VectorXd rss_target_;
};

}  // namespace mpm
