// OVERVIEW
// One square-root RLS update shared by a regression and its restricted
// models: the full model [A, B_1, ..., B_m] and the pairwise models [A, B_i],
// all with the same target y and forgetting (the Granger monitor's models of
// one output: A = [1, residual lags], B_i = the regressors of input i).
//
// Why it is cheaper than separate factors: in the upper-triangular factor of
// [A B_1 .. B_m y] the rows of the prefix A, [R_AA R_AB_1 .. R_AB_m R_Ay], are
// the same in every model that starts with A (they depend only on the Gram
// matrix's A rows), and so are the rotations that absorb a new sample
// into them. What differs between the models is only the factor of what A
// leaves unexplained: the Schur complement of [B_1 .. B_m y] (full model) or
// of [B_i y] (pairwise model i) given A. So one trapezoid of A rows absorbs
// the sample once, and what the rotations leave of the row, [w_B1 .. w_Bm,
// w_y], goes on to one lower factor over [B_1 .. B_m, y] and to one small
// factor over [B_i, y] per input i > 1 (the first input's pairwise model is
// a prefix of the full lower factor). Each model's factor is then exactly
// what a separate fit of that model would hold; the pairwise models cost
// O(nb^2) instead of O((na + nb)^2) per sample.
//
// Factors: the trapezoid and the lower factors are square-root free (R =
// D^1/2 U, ud_rls.hpp): what the trapezoid's rotations leave of the row
// goes on with the weight they leave it. With wald_tests, the full lower
// factor is kept in covariance form instead (bierman_rls.hpp), which gives
// every block's conditional RSS by the Wald identity; it has no prefix
// models, so the first input's pairwise model gets a factor of its own too.
// The lower factor is one of the two (a variant), fixed at setup.
//
// Priors: the A directions' prior lives in the trapezoid and is kept alive as
// in every factor (rls_common.hpp: a unit row every K samples, absorbed without forgetting and
// passed on to every lower factor); each lower factor keeps its own B
// directions' prior alive itself.
#pragma once

#include <cstddef>
#include <variant>
#include <vector>

#include <Eigen/Dense>

#include "core/bierman_rls.hpp"
#include "core/rls_common.hpp"
#include "core/ud_rls.hpp"

namespace mpm {

class NestedRls {
 public:
  using Matrix = RlsMatrix;

  NestedRls() = default;
  // prefix = |A| >= 1, blocks = m >= 1, block_size = |B_i| >= 1, forgetting
  // in (0, 1], regularization > 0. wald_tests: the full lower factor in
  // covariance form, for rss_without_block by the Wald identity (m nb must
  // then be whole blocks of nb, as it is).
  NestedRls(std::size_t prefix, std::size_t blocks, std::size_t block_size, double forgetting,
            double regularization = 1e-9, bool wald_tests = false);

  std::size_t prefix() const noexcept { return a_; }
  std::size_t blocks() const noexcept { return m_; }
  std::size_t block_size() const noexcept { return nb_; }
  std::size_t n_regressors() const noexcept { return a_ + m_ * nb_; }

  // Real-time safe. x: n_regressors() values [A, B_1 .. B_m], y: target.
  void update(const double* x, double y) noexcept;
  // The same in two steps (see UdRls::update_staged): write x then y into
  // staged_row() (n_regressors() + 1 values) of each model, then
  // update_staged() interleaves the rotations of all of them.
  double* staged_row() noexcept { return row_.data(); }
  // `models`: an array of `count` of them.
  static void update_staged(NestedRls* models, std::size_t count) noexcept;

  // Weighted residual sums of squares:
  // of the model of the first k <= prefix() regressors of A,
  double rss_head(std::size_t k) const noexcept;
  // of the model of A alone (the paper's Sigma1 times the weight sum),
  double rss_prefix_only() const noexcept {
    const UdRls* ud = information_lower();
    return ud ? ud->rss_prefix(0) : std::get<BiermanRls>(lower_).rss_empty();
  }
  // of the full model,
  double rss_full() const noexcept {
    return std::visit([](const auto& lower) { return lower.rss(); }, lower_);
  }
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

  // What the last update's sample was before it was absorbed, as the
  // trapezoid of [1, AR] left it: m nb values x~ (the input regressors'
  // a-priori residuals given A) then e (the a-priori AR-only prediction
  // error), all with weight apriori_weight() (the conversion factor). The
  // sequential detector's score is apriori_weight() * e * x~. Real-time safe.
  const double* apriori_row() const noexcept { return apriori_.data(); }
  double apriori_weight() const noexcept { return apriori_weight_; }
  // s^T S^-1 s for S the information of the inputs' block given A (the
  // lower factor's [B] block: U^T D U, or P^-1 in covariance form). `scratch`:
  // at least m nb values. Real-time safe; one triangular solve.
  double information_quadratic(const double* s, double* scratch) const noexcept;
  // S itself (information form only: !wald_tests), m nb x m nb column major.
  // O((m nb)^3) real-time safe: for a periodic refresh.
  void inputs_information(double* out, std::size_t ld) const noexcept;
  bool covariance_form() const noexcept { return std::holds_alternative<BiermanRls>(lower_); }
  // S^-1 (m nb x m nb, column major, leading dimension ld). O((m nb)^3),
  // real-time safe: for a raise, not for every sample.
  void inputs_covariance(double* out, std::size_t ld) const noexcept;

  // Back to the prior.
  void reset() noexcept;

  // Calls v(member) for every member that changes after setup, in a fixed
  // order: what a checkpoint saves and restores (daemon/mpmd/checkpoint.hpp).
  // The lower factor is saved in the place of its form, an empty factor in
  // that of the other (the layout of checkpoints written before the two
  // forms were one variant, so those still load).
  template <class V>
  void visit_state(V&& v) {
    v(prior_); v(top_); v(top_d_);
    if (UdRls* ud = std::get_if<UdRls>(&lower_)) {
      BiermanRls none;
      v(*ud); v(none);
    } else {
      UdRls none;
      v(none); v(std::get<BiermanRls>(lower_));
    }
    v(pairs_);
    v(row_); v(row_weight_); v(apriori_); v(apriori_weight_);
  }

 private:
  std::size_t a_ = 0;
  std::size_t m_ = 0;
  std::size_t nb_ = 0;
  std::size_t cols_ = 0;          // a + m nb + 1
  double lambda_ = 1.0;
  double delta_ = 1e-9;
  KeptAlivePrior prior_;           // over the rows of A (the lower factors keep their own)
  Matrix top_;                    // a x (padded cols + lanes): the A rows of U, [U_AA U_AB U_Ay]
  Eigen::VectorXd top_d_;         // their weights (D)
  // [B_1 .. B_m | y] given A: information form (its prefix [B_1 | y] is the
  // first pairwise model) or covariance form (Wald tests).
  std::variant<UdRls, BiermanRls> lower_;
  std::vector<UdRls> pairs_;      // [B_i | y] given A, i = 2..m (i = 1..m in covariance form)
  std::size_t first_pair_ = 1;    // the input of pairs_[0]: 1, or 0 in covariance form
  Eigen::VectorXd row_;           // staged row, cols values
  double row_weight_ = 1.0;       // its weight after the trapezoid's rotations
  Eigen::VectorXd apriori_;       // the last sample's row as the trapezoid left it (m nb + 1)
  double apriori_weight_ = 0.0;
  mutable Eigen::VectorXd coef_b_;  // scratch: B coefficients (m nb)
  mutable Eigen::MatrixXd pair_beta_b_;  // padded(nb) x m: beta_B_i, zero padded
  mutable Eigen::MatrixXd pair_rhs_;     // a x m: U_Ay - U_AB_i beta_B_i
  mutable Eigen::MatrixXd pair_prefix_;  // padded(a) x m: solve_pairs_prefix's result

  // The lower factor in information form, or null in covariance form.
  const UdRls* information_lower() const noexcept { return std::get_if<UdRls>(&lower_); }
  // The factor of pairwise model i: the prefix of the information-form
  // lower factor for i = 0, else its own (its first nb regressors are B_i's
  // either way).
  const UdRls& pair_factor(std::size_t i) const noexcept {
    const UdRls* ud = information_lower();
    return i < first_pair_ ? *ud : pairs_[i - first_pair_];
  }
  // Rotates row_ through the trapezoid rows [first, a), forgetting lambda.
  void absorb_top(std::size_t first, double lambda) noexcept;
  // Hands what is left of row_ to the lower factors as their staged rows.
  void stage_lowers() noexcept;
  // Same, absorbed at once without forgetting (the trapezoid's prior row).
  void add_to_lowers() noexcept;
  void refresh_prior() noexcept;
  // U_AA beta_A = rhs for `count` right-hand sides (columns of a values,
  // stride a) into columns of stride out_stride (unit diagonal: no division).
  void solve_top_unit(const double* rhs, std::size_t count, double* out, std::size_t out_stride) const noexcept;
  // U_AA beta_A = U_Ay - U_AB beta_B for the B columns [b0, b0 + count).
  void solve_top(std::size_t b0, std::size_t count, const double* beta_b, double* beta_a) const noexcept;
};

}  // namespace mpm
