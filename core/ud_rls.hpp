// OVERVIEW
// Square-root-free recursive least squares with exponential forgetting: the
// same factor as the textbook square-root form (SqrtRls, tests/support),
// kept as R = D^1/2 U (U unit upper triangular, D
// diagonal weights) and updated by Gentleman's square-root-free Givens
// rotations (givens.hpp). Each absorbed row costs three operations per
// entry instead of four and one division per row instead of a square root
// and a division: the monitor's factor wherever it does not need the
// covariance's blocks (there BiermanRls keeps the covariance itself).
//
// What the monitor reads is as cheap as from R: with z the target column of
// U, the RSS of the model of the first k regressors is
//   d_p + sum_{i = k..p-1} d_i z_i^2,
// and its coefficients solve U[0:k, 0:k] beta = z[0:k] (unit diagonal: no
// divisions). Rows come with a weight (a row left over from another
// factor's rotations carries the weight they left it, see NestedRls).
//
// The prior (regularization per regressor) is kept alive by one scaled unit
// row every K samples, round robin (rls_common.hpp, KeptAlivePrior).
#pragma once

#include <cstddef>
#include <cstdint>

#include <Eigen/Dense>

#include "core/rls_common.hpp"

namespace mpm {

class UdRls {
 public:
  using Matrix = RlsMatrix;

  UdRls() = default;
  // n_regressors >= 1, forgetting in (0, 1], regularization > 0.
  UdRls(std::size_t n_regressors, double forgetting, double regularization = 1e-9);

  // Real-time safe. x: n_regressors values, y: target, weight >= 0.
  void update(const double* x, double y, double weight = 1.0) noexcept;
  // Absorbs one row without forgetting (a prior row, or the part of one that
  // a shared factor passes on). Real-time safe.
  void add_row(const double* x, double y, double weight = 1.0) noexcept;
  // update() in two steps, for updating independent models together: write
  // x then y into staged_row() (n_regressors + 1 values) and the weight with
  // stage_weight(), then update_staged() interleaves their rotations so the
  // divisions' latencies overlap. Each ends exactly as if updated alone.
  double* staged_row() noexcept { return work_.data(); }
  void stage_weight(double weight) noexcept { work_weight_ = weight; }
  static void update_staged(UdRls* const* models, std::size_t count) noexcept;

  std::size_t n_regressors() const noexcept { return p_; }
  // Weighted RSS of the model of the first k regressors (k = 0: of y alone).
  // Real-time safe; the suffix sums are computed once per change.
  double rss_prefix(std::size_t k) const noexcept;
  double rss() const noexcept { return d_[static_cast<Eigen::Index>(p_)]; }
  // Weighted RSS of the model that leaves out regressors [first,
  // first+count): rows [first, p] of R re-triangularised in `scratch` (at
  // least (p+1) x (p+1), overwritten), as retriangularised_rss. Real-time safe.
  double rss_without(std::size_t first, std::size_t count, Matrix& scratch) const noexcept;
  // Coefficients of the model of the first k regressors into out[0..k).
  void solve_prefix(std::size_t k, Eigen::Ref<Eigen::VectorXd> out) const noexcept;
  // The same into `out` with room for padded(k) values, the ones past k
  // left zero.
  void solve_prefix_padded(std::size_t k, double* out) const noexcept;
  // R = D^1/2 U, (p+1) x (p+1) upper triangular, target last (allocates;
  // for comparisons, not for the hot path).
  Matrix factor() const;
  // U ((p+1) x (p+1), unit diagonal) and D as kept.
  Eigen::Ref<const Matrix> unit_factor() const noexcept { return u_.leftCols(static_cast<Eigen::Index>(p_ + 1)); }
  const Eigen::VectorXd& weights() const noexcept { return d_; }
  void reset() noexcept;

  // Calls v(member) for every member that changes after setup, in a fixed
  // order: what a checkpoint saves and restores (daemon/mpmd/checkpoint.hpp).
  template <class V>
  void visit_state(V&& v) {
    v(prior_); v(u_); v(d_); v(work_); v(work_weight_); v(changes_); v(rss_stamp_); v(rss_tail_);
  }

 private:
  std::size_t p_ = 0;
  double lambda_ = 1.0;
  double delta_ = 1e-9;
  KeptAlivePrior prior_;
  Matrix u_;                 // (p+1) x padded(p+1), unit diagonal
  Eigen::VectorXd d_;        // p+1 diagonal weights; d_p = RSS of the full model
  Eigen::VectorXd work_;     // row being absorbed, p+1 values and padding
  double work_weight_ = 1.0;
  std::uint64_t changes_ = 0;
  mutable std::uint64_t rss_stamp_ = ~std::uint64_t{0};
  mutable Eigen::VectorXd rss_tail_;  // rss_prefix(k), k = 0..p, when rss_stamp_ == changes_

  void absorb(std::size_t first, double lambda) noexcept;  // work_ from row `first` on
  void solve(std::size_t k, double* beta) const noexcept;   // beta[0..k) only
  void refresh_prior() noexcept;
};

}  // namespace mpm
