// OVERVIEW
// Covariance-form recursive least squares with exponential forgetting, the
// covariance kept as P = U D U^T (U unit upper triangular, D diagonal) and
// updated by Bierman's square-root-free measurement update (Bierman,
// "Factorization Methods for Discrete Sequential Estimation", 1977), for
// the one thing the information-form factors (UdRls; SqrtRls in the tests) do
// expensively: the conditional test of every block of a large regression.
//
// Why: by the Wald identity the RSS of the model without block b is
//   RSS + beta_b^T [P]_bb^-1 beta_b,
// so a test per block needs the coefficients and P's diagonal blocks. An
// information-form factor R has to carry R^-T beside it to get them (twice
// the state, twice the passes); P = U D U^T gives them directly. The update
// reads and writes U once, column by column (column j's part of U^T x is
// formed just before the column is updated, from its old values), with three
// multiply-adds per entry and no square root: half the memory traffic and a
// third of the arithmetic of an information factor carrying R^-T, which
// matters once the factors outgrow the caches (50 inputs: 1 MB per output).
//
// Tracked beside U and D: the coefficients (beta += K e), the RSS (+= lambda
// e^2 / alpha, the innovation's weight), the target's energy (the RSS of the
// empty model), and the diagonal blocks of P (each downdated by the gain,
// one recomputed from U and D per sample so rounding cannot accumulate).
// Numerically this is the stable covariance update (no P - K h^T P
// subtraction of large numbers); beta and the RSS are recursions, so they
// are checked against the information-form factor in the tests.
//
// Poor excitation: the prior of `regularization` per regressor is kept alive
// by a scaled unit row every K samples, round robin (rls_common.hpp).
#pragma once

#include <cstddef>
#include <cstdint>

#include <Eigen/Dense>

#include "core/rls_common.hpp"

namespace mpm {

class BiermanRls {
 public:
  using Matrix = RlsMatrix;

  BiermanRls() = default;
  // n_regressors a multiple of block >= 1; forgetting in (0, 1];
  // regularization > 0 (P starts as I / regularization).
  BiermanRls(std::size_t n_regressors, std::size_t block, double forgetting, double regularization = 1e-9);

  // Real-time safe. x: n_regressors values, y: target, weight >= 0.
  void update(const double* x, double y, double weight = 1.0) noexcept;
  // The same in two steps: write x then y into staged_row() and the weight
  // with stage_weight(), then update_staged().
  double* staged_row() noexcept { return h_.data(); }
  void stage_weight(double weight) noexcept { staged_weight_ = weight; }
  void update_staged() noexcept;
  // A row absorbed without forgetting (a prior row, or what another factor
  // passes on). Real-time safe.
  void add_row(const double* x, double y, double weight = 1.0) noexcept;

  std::size_t n_regressors() const noexcept { return p_; }
  std::size_t block() const noexcept { return nb_; }
  double rss() const noexcept { return rss_; }
  // RSS of the model without regressors (the target's weighted energy).
  double rss_empty() const noexcept { return energy_; }
  // RSS of the model without block i (regressors [i nb, (i + 1) nb)), by the
  // Wald identity. `scratch`: at least (nb + 1) x nb, overwritten.
  double rss_without_block(std::size_t i, Matrix& scratch) const noexcept;
  const Eigen::VectorXd& coefficients() const noexcept { return theta_; }
  // P = U D U^T as a dense matrix (allocates; for tests).
  Eigen::MatrixXd covariance() const;
  // s^T P s (the sequential detector's normalisation): one pass over U.
  // Real-time safe.
  double covariance_quadratic(const double* s) const noexcept;
  // P into out (p x p, column major, leading dimension ld). O(p^3), real-time
  // safe (for a raise, not every sample).
  void covariance_into(double* out, std::size_t ld) const noexcept;
  void reset() noexcept;

  // Calls v(member) for every member that changes after setup, in a fixed
  // order: what a checkpoint saves and restores (daemon/mpmd/checkpoint.hpp).
  template <class V>
  void visit_state(V&& v) {
    v(prior_); v(u_); v(d_); v(theta_); v(h_); v(gain_); v(block_cov_);
    v(next_resync_); v(staged_weight_); v(rss_); v(energy_);
  }

 private:
  std::size_t p_ = 0;
  std::size_t nb_ = 0;
  double lambda_ = 1.0;
  double delta_ = 1e-9;
  KeptAlivePrior prior_;
  Eigen::VectorXd u_;          // column j of U above the diagonal at column_[j], padded(j) values
  Eigen::Matrix<std::size_t, Eigen::Dynamic, 1> column_;  // offsets into u_
  Eigen::VectorXd d_;          // D
  Eigen::VectorXd theta_;      // coefficients
  Eigen::VectorXd h_;          // the row being absorbed: p values, padding, then y at p_padded
  Eigen::VectorXd gain_;       // P h (unnormalised gain), padded
  Matrix block_cov_;           // p x nb: block b's [P]_bb (lower triangle) in its rows
  std::size_t next_resync_ = 0;
  double staged_weight_ = 1.0;
  double rss_ = 0.0;
  double energy_ = 0.0;

  // Absorbs h_ (target at h_[p]) with `weight`; `lambda` forgets the past
  // first (1: none). Without forgetting, h_[0, first) == 0 may be promised:
  // those columns would see f_j = 0 and keep their values, so they are
  // skipped (the kept-alive prior's unit rows: half the work on average).
  void absorb(double weight, double lambda, std::size_t first = 0) noexcept;
  // [P]_bb of the block starting at b0 from U and D, lower triangle, into
  // rows of `out` (stride `ld`).
  void block_covariance_from_factor(std::size_t b0, double* out, std::size_t ld) const noexcept;
  void refresh_prior() noexcept;
};

}  // namespace mpm
