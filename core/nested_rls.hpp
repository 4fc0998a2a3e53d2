// OVERVIEW
// One square-root RLS update shared by a regression and its restricted
// models: the full model [A, B_1, ..., B_m] and the pairwise models [A, B_i],
// all with the same target y and forgetting (the Granger monitor's models of
// one output: A = [1, residual lags], B_i = the regressors of input i).
//
// Why it is cheaper than separate factors: in the upper-triangular factor of
// [A B_1 .. B_m y] the rows of the prefix A, [R_AA R_AB_1 .. R_AB_m R_Ay], are
// the same in every model that starts with A (they depend only on the Gram
// matrix's A rows), and so are the Givens rotations that absorb a new sample
// into them. What differs between the models is only the factor of what A
// leaves unexplained: the Schur complement of [B_1 .. B_m y] (full model) or
// of [B_i y] (pairwise model i) given A. So one trapezoid of A rows absorbs
// the sample once, and what the rotations leave of the row, [w_B1 .. w_Bm,
// w_y], goes on to one lower SqrtRls over [B_1 .. B_m, y] and to one small
// SqrtRls over [B_i, y] per input i > 1 (the first input's pairwise model is
// a prefix of the full lower factor). Each model's factor is then exactly
// what a separate SqrtRls of that model would hold; the pairwise models cost
// O(nb^2) instead of O((na + nb)^2) per sample.
//
// Priors: the A directions' prior lives in the trapezoid and is kept alive as
// in SqrtRls (a unit row every K samples, absorbed without forgetting and
// passed on to every lower factor); each lower factor keeps its own B
// directions' prior alive itself.
#pragma once

#include <cstddef>
#include <vector>

#include <Eigen/Dense>

#include "core/sqrt_rls.hpp"

namespace mpm {

class NestedRls {
 public:
  using Matrix = SqrtRls::Matrix;

  NestedRls() = default;
  // prefix = |A| >= 1, blocks = m >= 1, block_size = |B_i| >= 1, forgetting
  // in (0, 1], regularization > 0. track_inverse: the full lower factor also
  // carries its inverse, for rss_without_block by the Wald identity.
  NestedRls(std::size_t prefix, std::size_t blocks, std::size_t block_size, double forgetting,
            double regularization = 1e-9, bool track_inverse = false);

  std::size_t prefix() const noexcept { return a_; }
  std::size_t blocks() const noexcept { return m_; }
  std::size_t block_size() const noexcept { return nb_; }
  std::size_t n_regressors() const noexcept { return a_ + m_ * nb_; }

  // Real-time safe. x: n_regressors() values [A, B_1 .. B_m], y: target.
  void update(const double* x, double y) noexcept;
  // The same in two steps (see SqrtRls::update_staged): write x then y into
  // staged_row() (n_regressors() + 1 values) of each model, then
  // update_staged() interleaves the rotations of all of them.
  double* staged_row() noexcept { return row_.data(); }
  // `models`: an array of `count` of them.
  static void update_staged(NestedRls* models, std::size_t count) noexcept;

  // Weighted residual sums of squares:
  // of the model of the first k <= prefix() regressors of A,
  double rss_head(std::size_t k) const noexcept;
  // of the model of A alone (the paper's Sigma1 times the weight sum),
  double rss_prefix_only() const noexcept { return lower_.rss_prefix(0); }
  // of the full model,
  double rss_full() const noexcept { return lower_.rss(); }
  // of the pairwise model [A, B_i] and of its own A-only part (equal to
  // rss_prefix_only() but for the rounding and priors of its own factor),
  double rss_pair(std::size_t i) const noexcept;
  double rss_pair_prefix_only(std::size_t i) const noexcept;
  // of the full model without block i: free for m <= 2 (a pairwise or a
  // prefix model), else re-triangularisation of the lower factor or, with
  // the inverse tracked, the Wald identity. `scratch`: at least
  // (m nb + 1) x (m nb + 1), overwritten. Real-time safe.
  double rss_without_block(std::size_t i, Matrix& scratch) const noexcept;

  // Coefficients of A in the pairwise model [A, B_i] (prefix() values into
  // out). Real-time safe.
  void solve_pair_prefix(std::size_t i, Eigen::Ref<Eigen::VectorXd> out) const noexcept;
  // The same for every pairwise model at once (one pass over R_AA serves
  // all): column i holds the A coefficients of [A, B_i] in its first
  // prefix() rows (then zero padding). The result lives
  // until the next call. Real-time safe.
  const Eigen::MatrixXd& solve_pairs_prefix() const noexcept;
  // All coefficients of the full model (n_regressors() values). Real-time safe.
  void solve_full(Eigen::Ref<Eigen::VectorXd> out) const noexcept;

  // Back to the prior.
  void reset() noexcept;

 private:
  std::size_t a_ = 0;
  std::size_t m_ = 0;
  std::size_t nb_ = 0;
  std::size_t cols_ = 0;          // a + m nb + 1
  double sqrt_lambda_ = 1.0;
  double inv_sqrt_lambda_ = 1.0;
  double delta_ = 1e-9;
  bool forgets_ = false;
  int prior_period_ = 1;
  int since_prior_ = 0;
  double prior_weight_ = 0.0;
  std::size_t next_prior_row_ = 0;
  Matrix top_;                    // a x (padded cols + lanes): the A rows [R_AA R_AB R_Ay]
  Matrix top_inv_;                // a x a lower triangular R_AA^-T, carried
                                  // through the same rotations (sqrt_rls.hpp):
                                  // the pairwise coefficients without a
                                  // back substitution's dependency chain
  Eigen::VectorXd row_inv_;       // its counterpart of row_
  SqrtRls lower_;                 // [B_1 .. B_m | y] given A
  std::vector<SqrtRls> pairs_;    // [B_i | y] given A, i = 2..m
  Eigen::VectorXd row_;           // staged row, cols values
  mutable Eigen::VectorXd coef_b_;  // scratch: B coefficients (m nb)
  mutable Eigen::MatrixXd pair_beta_b_;  // padded(nb) x m: beta_B_i, zero padded
  mutable Eigen::MatrixXd pair_rhs_;     // a x m: R_Ay - R_AB_i beta_B_i
  mutable Eigen::MatrixXd pair_prefix_;  // padded(a) x m: solve_pairs_prefix's result

  // Rotates row_ through the trapezoid rows [first, a) with `scale`.
  void absorb_top(std::size_t first, double scale) noexcept;
  // Hands what is left of row_ to the lower factors as their staged rows.
  void stage_lowers() noexcept;
  // Same, absorbed at once with weight 1 (the trapezoid's prior row).
  void add_to_lowers() noexcept;
  void refresh_prior() noexcept;
  // Rotation i of the trapezoid (and of R_AA^-T) against row_.
  void rotate_top_row(std::size_t i, double scale) noexcept;
  // out = R_AA^-1 rhs (a values each).
  void apply_top_inverse(const double* rhs, double* out) const noexcept;
  // R_AA beta_A = R_Ay - R_AB beta_B for the B columns [b0, b0 + count).
  void solve_top(std::size_t b0, std::size_t count, const double* beta_b, double* beta_a) const noexcept;
};

}  // namespace mpm
