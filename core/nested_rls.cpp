#include "core/nested_rls.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/givens.hpp"

namespace mpm {
namespace {

// Lower factors updated together (SqrtRls::update_staged): enough
// independent rotation chains to hide the square-root and division latency.
constexpr std::size_t kLockstep = 8;
// Factors with more regressors than this are updated alone: their rows are
// long enough to hide the latency by themselves, and one factor at a time
// walks its rows in memory order (a stream the prefetchers follow) instead
// of hopping between eight factors' short row segments.
constexpr std::size_t kLockstepMaxRegressors = 64;

}  // namespace

NestedRls::NestedRls(std::size_t prefix, std::size_t blocks, std::size_t block_size, double forgetting,
                     double regularization, bool track_inverse)
    : a_(prefix),
      m_(blocks),
      nb_(block_size),
      cols_(prefix + blocks * block_size + 1),
      sqrt_lambda_(std::sqrt(forgetting)),
      inv_sqrt_lambda_(1.0 / std::sqrt(forgetting)),
      delta_(regularization),
      forgets_(forgetting < 1.0) {
  if (prefix == 0 || blocks == 0 || block_size == 0)
    throw std::invalid_argument("NestedRls: need a prefix and at least one block of regressors");
  if (!(forgetting > 0.0 && forgetting <= 1.0)) throw std::invalid_argument("NestedRls: forgetting must be in (0, 1]");
  if (!(regularization > 0.0)) throw std::invalid_argument("NestedRls: regularization must be > 0");
  prior_period_ = givens::prior_period(a_, forgetting);
  prior_weight_ = givens::prior_weight(a_, prior_period_, forgetting, delta_);
  // One spare block of lanes past the padded width (always zero): whole-lane
  // reads of a block of B columns may run past the last one.
  top_.resize(static_cast<Eigen::Index>(a_), static_cast<Eigen::Index>(givens::padded(cols_) + givens::kLanes));
  lower_ = SqrtRls(m_ * nb_, forgetting, regularization, track_inverse, track_inverse ? nb_ : 0);
  pairs_.assign(m_ - 1, SqrtRls(nb_, forgetting, regularization));
  row_ = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(givens::padded(cols_)));
  top_inv_.resize(static_cast<Eigen::Index>(a_), static_cast<Eigen::Index>(givens::padded(a_)));
  row_inv_ = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(givens::padded(a_)));
  pair_rhs_.resize(static_cast<Eigen::Index>(a_), static_cast<Eigen::Index>(m_));
  coef_b_.resize(static_cast<Eigen::Index>(m_ * nb_));
  pair_beta_b_ = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(givens::padded(nb_)), static_cast<Eigen::Index>(m_));
  pair_prefix_.resize(static_cast<Eigen::Index>(givens::padded(a_)), static_cast<Eigen::Index>(m_));
  reset();
}

void NestedRls::reset() noexcept {
  top_.setZero();
  top_inv_.setZero();
  for (std::size_t i = 0; i < a_; ++i) {
    const auto ii = static_cast<Eigen::Index>(i);
    top_(ii, ii) = std::sqrt(delta_);
    top_inv_(ii, ii) = 1.0 / std::sqrt(delta_);
  }
  lower_.reset();
  for (SqrtRls& p : pairs_) p.reset();
  since_prior_ = 0;
  next_prior_row_ = 0;
}

void NestedRls::absorb_top(std::size_t first, double scale) noexcept {
  row_inv_.setZero();
  for (std::size_t i = first; i < a_; ++i) rotate_top_row(i, scale);
}

// Inlined into the lockstep loop, as SqrtRls::absorb_row.
[[gnu::always_inline]] inline void NestedRls::rotate_top_row(std::size_t i, double scale) noexcept {
  const auto ii = static_cast<Eigen::Index>(i);
  const givens::Rotation rot = givens::rotate(top_.row(ii).data(), row_.data(), i, givens::padded(cols_), scale);
  const double inv_scale = scale == sqrt_lambda_ ? inv_sqrt_lambda_ : 1.0 / scale;
  givens::rotate_inverse(top_inv_.row(ii).data(), row_inv_.data(), i + 1, rot, inv_scale);
}

void NestedRls::stage_lowers() noexcept {
  const double* w = row_.data();
  const double y = w[cols_ - 1];
  std::copy(w + a_, w + cols_, lower_.staged_row());  // B_1 .. B_m, y
  for (std::size_t i = 1; i < m_; ++i) {
    double* q = pairs_[i - 1].staged_row();
    std::copy(w + a_ + i * nb_, w + a_ + (i + 1) * nb_, q);
    q[nb_] = y;
  }
}

void NestedRls::add_to_lowers() noexcept {
  const double* w = row_.data();
  const double y = w[cols_ - 1];
  lower_.add_row(w + a_, y);
  for (std::size_t i = 1; i < m_; ++i) pairs_[i - 1].add_row(w + a_ + i * nb_, y);
}

void NestedRls::update(const double* x, double y) noexcept {
  std::copy(x, x + (cols_ - 1), row_.data());
  row_[static_cast<Eigen::Index>(cols_ - 1)] = y;
  update_staged(this, 1);
}

void NestedRls::update_staged(NestedRls* models, std::size_t count) noexcept {
  // The trapezoids' rotation i of every model, then rotation i + 1, so the
  // models' chains of dependent square roots and divisions overlap.
  std::size_t rows = 0;
  for (std::size_t k = 0; k < count; ++k) rows = std::max(rows, models[k].a_);
  for (std::size_t k = 0; k < count; ++k) models[k].row_inv_.setZero();
  for (std::size_t i = 0; i < rows; ++i)
    for (std::size_t k = 0; k < count; ++k)
      if (i < models[k].a_) models[k].rotate_top_row(i, models[k].sqrt_lambda_);
  // Then every lower factor, a few at a time.
  SqrtRls* group[kLockstep];
  std::size_t in_group = 0;
  const auto add = [&](SqrtRls& lower) {
    if (lower.n_regressors() > kLockstepMaxRegressors) {
      SqrtRls* alone = &lower;
      SqrtRls::update_staged(&alone, 1);
      return;
    }
    group[in_group++] = &lower;
    if (in_group == kLockstep) {
      SqrtRls::update_staged(group, in_group);
      in_group = 0;
    }
  };
  for (std::size_t k = 0; k < count; ++k) {
    NestedRls& n = models[k];
    n.stage_lowers();
    add(n.lower_);
    for (SqrtRls& p : n.pairs_) add(p);
  }
  if (in_group > 0) SqrtRls::update_staged(group, in_group);
  for (std::size_t k = 0; k < count; ++k) models[k].refresh_prior();
}

void NestedRls::refresh_prior() noexcept {
  if (!forgets_ || ++since_prior_ < prior_period_) return;
  since_prior_ = 0;
  double* w = row_.data();
  std::fill(w, w + cols_, 0.0);
  w[next_prior_row_] = prior_weight_;
  absorb_top(next_prior_row_, 1.0);
  add_to_lowers();
  next_prior_row_ = (next_prior_row_ + 1) % a_;
}

double NestedRls::rss_head(std::size_t k) const noexcept {
  const auto target = static_cast<Eigen::Index>(cols_ - 1);
  double s = rss_prefix_only();
  for (std::size_t r = k; r < a_; ++r) {
    const double v = top_(static_cast<Eigen::Index>(r), target);
    s += v * v;
  }
  return s;
}

double NestedRls::rss_pair(std::size_t i) const noexcept {
  return i == 0 ? lower_.rss_prefix(nb_) : pairs_[i - 1].rss();
}

double NestedRls::rss_pair_prefix_only(std::size_t i) const noexcept {
  return i == 0 ? lower_.rss_prefix(0) : pairs_[i - 1].rss_prefix(0);
}

double NestedRls::rss_without_block(std::size_t i, Matrix& scratch) const noexcept {
  if (m_ == 1) return rss_prefix_only();
  // Two inputs: the model without one is the pairwise model of the other.
  if (m_ == 2) return i == 0 ? pairs_[0].rss() : lower_.rss_prefix(nb_);
  return lower_.rss_without_wald(i * nb_, nb_, scratch);
}

void NestedRls::apply_top_inverse(const double* rhs, double* out) const noexcept {
  // out = R_AA^-1 rhs = L^T rhs with L = R_AA^-T lower triangular and
  // row-major: an AXPY of row r of L per right-hand side entry, with no
  // dependency chain (a back substitution waits on every coefficient in turn).
  std::fill(out, out + a_, 0.0);
  for (std::size_t r = 0; r < a_; ++r) {
    const double* l = top_inv_.row(static_cast<Eigen::Index>(r)).data();
    const double t = rhs[r];
    for (std::size_t k = 0; k <= r; ++k) out[k] += t * l[k];
  }
}

void NestedRls::solve_top(std::size_t b0, std::size_t count, const double* beta_b, double* beta_a) const noexcept {
  // R_AA beta_A = R_Ay - R_AB beta_B.
  const auto target = static_cast<Eigen::Index>(cols_ - 1);
  double* rhs = pair_rhs_.col(0).data();
  for (std::size_t r = 0; r < a_; ++r) {
    const double* row = top_.row(static_cast<Eigen::Index>(r)).data() + a_ + b0;
    double v = top_(static_cast<Eigen::Index>(r), target);
    for (std::size_t c = 0; c < count; ++c) v -= row[c] * beta_b[c];
    rhs[r] = v;
  }
  apply_top_inverse(rhs, beta_a);
}

const Eigen::MatrixXd& NestedRls::solve_pairs_prefix() const noexcept {
  using givens::Lanes;
  using givens::load;
  constexpr std::size_t kLanes = givens::kLanes;
  const std::size_t target = cols_ - 1;
  const std::size_t nb_padded = givens::padded(nb_);
  // beta_B_i of every pairwise model, each zero-padded to whole lanes.
  for (std::size_t i = 0; i < m_; ++i) {
    double* beta_b = pair_beta_b_.col(static_cast<Eigen::Index>(i)).data();
    if (i == 0) lower_.solve_prefix_padded(nb_, beta_b);
    else pairs_[i - 1].solve_prefix_padded(nb_, beta_b);
  }
  // Right-hand sides R_Ay - R_AB_i beta_B_i, one column each: a dot product
  // of whole lanes per row (the lanes past B_i meet beta's zero padding;
  // top_ has a spare block of lanes so the last block stays inside the row),
  // four rows' reductions done together.
  const double* top = top_.data();
  const auto top_ld = static_cast<std::size_t>(top_.cols());
  const double* betas = pair_beta_b_.data();
  double* rhs = pair_rhs_.data();
  const auto rhs_column = [&]<std::size_t kBlocks>(std::size_t i) {
    // kBlocks lanes per dot product when known at compile time (the short
    // blocks of the paper's orders: straight-line code), else nb_padded.
    const std::size_t blocks = kBlocks > 0 ? kBlocks : nb_padded / kLanes;
    const double* beta = betas + i * nb_padded;
    const auto dot = [&](std::size_t r) {
      const double* bi = top + r * top_ld + a_ + i * nb_;
      Lanes acc = {};
      for (std::size_t b = 0; b < blocks; ++b) acc += load(bi + b * kLanes) * load(beta + b * kLanes);
      return acc;
    };
    double* out = rhs + i * a_;
    std::size_t r = 0;
    for (; r + 4 <= a_; r += 4) {
      const Lanes y = {top[r * top_ld + target], top[(r + 1) * top_ld + target], top[(r + 2) * top_ld + target],
                       top[(r + 3) * top_ld + target]};
      givens::store(out + r, y - givens::sum4(dot(r), dot(r + 1), dot(r + 2), dot(r + 3)));
    }
    for (; r < a_; ++r) out[r] = top[r * top_ld + target] - givens::sum(dot(r));
  };
  for (std::size_t i = 0; i < m_; ++i) {
    switch (nb_padded / kLanes) {
      case 1: rhs_column.template operator()<1>(i); break;
      case 2: rhs_column.template operator()<2>(i); break;
      case 3: rhs_column.template operator()<3>(i); break;
      case 4: rhs_column.template operator()<4>(i); break;
      default: rhs_column.template operator()<0>(i); break;
    }
  }
  // pair_prefix = R_AA^-1 rhs = L^T rhs, L = R_AA^-T lower triangular: each
  // block of lanes of the result sums rows r >= its first column (rows above
  // are zero there), accumulated in registers, two inputs sharing each load
  // of L.
  const std::size_t a_padded = givens::padded(a_);
  const double* inv = top_inv_.data();
  const auto inv_ld = static_cast<std::size_t>(top_inv_.cols());
  double* prefix = pair_prefix_.data();
  for (std::size_t i = 0; i < m_; i += 2) {
    const bool two = i + 1 < m_;
    const double* rhs0 = rhs + i * a_;
    const double* rhs1 = two ? rhs0 + a_ : rhs0;
    double* out0 = prefix + i * a_padded;
    for (std::size_t k = 0; k < a_padded; k += kLanes) {
      Lanes acc0 = {};
      Lanes acc1 = {};
      const double* l = inv + k * inv_ld + k;
      for (std::size_t r = k; r < a_; ++r, l += inv_ld) {
        const Lanes lr = load(l);
        acc0 += rhs0[r] * lr;
        acc1 += rhs1[r] * lr;
      }
      givens::store(out0 + k, acc0);
      if (two) givens::store(out0 + a_padded + k, acc1);
    }
  }
  return pair_prefix_;
}

void NestedRls::solve_pair_prefix(std::size_t i, Eigen::Ref<Eigen::VectorXd> out) const noexcept {
  auto beta_b = coef_b_.head(static_cast<Eigen::Index>(nb_));
  if (i == 0) lower_.solve_prefix(nb_, beta_b);
  else pairs_[i - 1].solve_prefix(nb_, beta_b);
  solve_top(i * nb_, nb_, beta_b.data(), out.data());
}

void NestedRls::solve_full(Eigen::Ref<Eigen::VectorXd> out) const noexcept {
  lower_.solve_prefix(m_ * nb_, coef_b_);
  solve_top(0, m_ * nb_, coef_b_.data(), out.data());
  std::copy(coef_b_.data(), coef_b_.data() + m_ * nb_, out.data() + a_);
}

}  // namespace mpm
