#include "core/sqrt_rls.hpp"

#include "core/givens.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace mpm {
using givens::Rotation;
using givens::rotate;
using givens::rotate_inverse;

// From this many regressors on, each rotation prefetches the next row.
constexpr std::size_t kPrefetchMinRegressors = 64;

SqrtRls::SqrtRls(std::size_t n_regressors, double forgetting, double regularization, bool track_inverse,
                 std::size_t wald_block)
    : p_(n_regressors),
      lambda_(forgetting),
      sqrt_lambda_(std::sqrt(forgetting)),
      inv_sqrt_lambda_(1.0 / std::sqrt(forgetting)),
      delta_(regularization),
      track_inverse_(track_inverse) {
  if (n_regressors == 0) throw std::invalid_argument("SqrtRls: need at least one regressor");
  if (!(forgetting > 0.0 && forgetting <= 1.0)) throw std::invalid_argument("SqrtRls: forgetting must be in (0, 1]");
  if (!(regularization > 0.0)) throw std::invalid_argument("SqrtRls: regularization must be > 0");
  if (wald_block > 0 && (!track_inverse || n_regressors % wald_block != 0))
    throw std::invalid_argument("SqrtRls: block covariances need the tracked inverse and whole blocks");
  wald_block_ = wald_block;
  prior_period_ = givens::prior_period(p_, lambda_);
  prior_weight_ = givens::prior_weight(p_, prior_period_, lambda_, delta_);
  const auto n = static_cast<Eigen::Index>(p_ + 1);
  const auto width = static_cast<Eigen::Index>(givens::padded(p_ + 1));
  r_.resize(n, width);
  work_ = Eigen::VectorXd::Zero(width);
  rss_tail_ = Eigen::VectorXd::Zero(n);
  if (p_ >= kPrefetchMinRegressors) {  // update_in_one_pass's rows
    prior_work_ = Eigen::VectorXd::Zero(width);
    rss_target_ = Eigen::VectorXd::Zero(n);
    if (track_inverse) prior_work_inv_ = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(givens::padded(p_)));
  }
  if (track_inverse_) {
    const auto inv_width = static_cast<Eigen::Index>(givens::padded(p_));
    linv_.resize(n - 1, inv_width);
    work_inv_ = Eigen::VectorXd::Zero(inv_width);
  }
  if (wald_block_ > 0) {
    block_cov_.resize(n - 1, static_cast<Eigen::Index>(wald_block_));
    coef_ = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(givens::padded(p_)));
  }
  reset();
}

void SqrtRls::reset() noexcept {
  r_.setZero();
  for (std::size_t i = 0; i < p_; ++i) r_(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(i)) = std::sqrt(delta_);
  if (track_inverse_) {
    linv_.setZero();
    for (std::size_t i = 0; i < p_; ++i)
      linv_(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(i)) = 1.0 / std::sqrt(delta_);
  }
  if (wald_block_ > 0) {
    // P = I / delta: every block's covariance starts as a scaled identity.
    block_cov_.setZero();
    for (std::size_t i = 0; i < p_; ++i)
      block_cov_(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(i % wald_block_)) = 1.0 / delta_;
  }
  next_prior_row_ = 0;
  since_prior_ = 0;
  next_resync_ = 0;
  ++changes_;
}

void SqrtRls::absorb(std::size_t first, double scale) noexcept {
  if (track_inverse_) return absorb_with_inverse(first, scale);
  const std::size_t n = p_ + 1;
  const std::size_t width = givens::padded(n);
  double* w = work_.data();
  ++changes_;
  for (std::size_t i = first; i < n; ++i) rotate(r_.row(static_cast<Eigen::Index>(i)).data(), w, i, width, scale);
}

void SqrtRls::absorb_with_inverse(std::size_t first, double scale) noexcept {
  std::fill(work_inv_.data(), work_inv_.data() + p_, 0.0);
  for (std::size_t i = first; i <= p_; ++i) absorb_row(i, scale);
  downdate_block_covariances(1.0);  // only rows without forgetting come here
}

void SqrtRls::downdate_block_covariances(double growth) noexcept {
  downdate_block_covariances(growth, work_inv_.data());
}

void SqrtRls::downdate_block_covariances(double growth, const double* v) noexcept {
  ++changes_;
  if (wald_block_ == 0) return;
  // Rotations preserve the Gram matrix of the columns of [L / sqrt(lambda);
  // 0] (rows absorbed without forgetting: [L; 0]), which ends as [L'; v^T]:
  //   P / lambda = P' + v v^T,  P = (R^T R)^-1 = L^T L.
  // So each diagonal block of P' is the old one, grown by 1 / lambda, less
  // v_b v_b^T: O(p nb) instead of O(p^2 nb) from L. Lower triangles only.
  const std::size_t nb = wald_block_;
  for (std::size_t b0 = 0; b0 < p_; b0 += nb) {
    for (std::size_t r = 0; r < nb; ++r) {
      double* srow = block_cov_.row(static_cast<Eigen::Index>(b0 + r)).data();
      const double vr = v[b0 + r];
      for (std::size_t c = 0; c <= r; ++c) srow[c] = growth * srow[c] - vr * v[b0 + c];
    }
  }
}

void SqrtRls::resync_block_covariance(std::size_t b0) noexcept {
  // Rounding in the downdates is not self-correcting: one block a sample is
  // recomputed from L, S_b = M^T M with M = L[b0:p, b] (rows above b0 are
  // zero in these columns), so each block is exact again every p / nb samples.
  const std::size_t nb = wald_block_;
  for (std::size_t r = 0; r < nb; ++r) {
    double* srow = block_cov_.row(static_cast<Eigen::Index>(b0 + r)).data();
    std::fill(srow, srow + nb, 0.0);
  }
  for (std::size_t k = b0; k < p_; ++k) {
    const double* v = linv_.row(static_cast<Eigen::Index>(k)).data() + b0;
    const std::size_t len = std::min(nb, k - b0 + 1);  // lower triangular
    for (std::size_t r = 0; r < len; ++r) {
      double* srow = block_cov_.row(static_cast<Eigen::Index>(b0 + r)).data();
      const double vr = v[r];
      for (std::size_t c = 0; c <= r; ++c) srow[c] += vr * v[c];
    }
  }
}

const double* SqrtRls::coefficients_from_inverse() const noexcept {
  // beta = R^-1 z = L^T z, as AXPYs of L's rows (no dependency chain);
  // computed once per change of the factor, shared by all blocks' tests.
  if (coef_stamp_ == changes_) return coef_.data();
  coef_.setZero();
  double* beta = coef_.data();
  const auto target = static_cast<Eigen::Index>(p_);
  for (std::size_t r = 0; r < p_; ++r) {
    const double* l = linv_.row(static_cast<Eigen::Index>(r)).data();
    const double z = r_(static_cast<Eigen::Index>(r), target);
    const std::size_t stop = givens::padded(r + 1);  // zeros past the diagonal
    for (std::size_t k = 0; k < stop; ++k) beta[k] += z * l[k];
  }
  coef_stamp_ = changes_;
  return beta;
}

// Inlined into the lockstep loop: as a call, its prologue (stack realignment
// for vector spills, saved registers) costs a quarter of a short rotation.
[[gnu::always_inline]] inline void SqrtRls::absorb_row(std::size_t i, double scale) noexcept {
  const std::size_t n = p_ + 1;
  const auto ii = static_cast<Eigen::Index>(i);
  if (p_ >= kPrefetchMinRegressors && i + 1 < n) prefetch_row(i + 1);
  const Rotation rot = rotate(r_.row(ii).data(), work_.data(), i, givens::padded(n), scale);
  if (track_inverse_ && i < p_) {
    const double inv_scale = scale == sqrt_lambda_ ? inv_sqrt_lambda_ : 1.0 / scale;
    rotate_inverse(linv_.row(ii).data(), work_inv_.data(), i + 1, rot, inv_scale);
  }
}

void SqrtRls::prefetch_row(std::size_t i) const noexcept {
  // The part of row i of R (columns i..) and of R^-T (columns ..i) the next
  // rotation touches, one request per cache line: large factors live in L3
  // or memory, and each row is a short run the hardware prefetchers would
  // only pick up after a few misses.
  constexpr std::size_t kLine = 64 / sizeof(double);
  const double* r = r_.row(static_cast<Eigen::Index>(i)).data();
  for (std::size_t j = i / kLine * kLine; j < p_ + 1; j += kLine) __builtin_prefetch(r + j, 0, 2);
  if (track_inverse_ && i < p_) {
    const double* l = linv_.row(static_cast<Eigen::Index>(i)).data();
    for (std::size_t j = 0; j <= i; j += kLine) __builtin_prefetch(l + j, 0, 2);
  }
}

void SqrtRls::update(const double* x, double y) noexcept {
  std::copy(x, x + p_, work_.data());
  work_[static_cast<Eigen::Index>(p_)] = y;
  SqrtRls* self = this;
  update_staged(&self, 1);
}

void SqrtRls::add_row(const double* x, double y) noexcept {
  std::copy(x, x + p_, work_.data());
  work_[static_cast<Eigen::Index>(p_)] = y;
  absorb(0, 1.0);
}

void SqrtRls::update_staged(SqrtRls* const* models, std::size_t count) noexcept {
  if (count == 1 && models[0]->p_ >= kPrefetchMinRegressors) return models[0]->update_in_one_pass();
  // Rotation i of every model, then rotation i + 1: the models' chains of
  // dependent square roots and divisions overlap in the pipeline.
  std::size_t rows = 0;
  for (std::size_t m = 0; m < count; ++m) {
    SqrtRls& s = *models[m];
    rows = std::max(rows, s.p_ + 1);
    if (s.track_inverse_) std::fill(s.work_inv_.data(), s.work_inv_.data() + s.p_, 0.0);
  }
  for (std::size_t i = 0; i < rows; ++i)
    for (std::size_t m = 0; m < count; ++m)
      if (i <= models[m]->p_) models[m]->absorb_row(i, models[m]->sqrt_lambda_);  // forgetting folded in
  for (std::size_t m = 0; m < count; ++m) {
    SqrtRls& s = *models[m];
    s.downdate_block_covariances(1.0 / s.lambda_);
    if (s.wald_block_ > 0) {
      s.resync_block_covariance(s.next_resync_);
      s.next_resync_ = (s.next_resync_ + s.wald_block_) % s.p_;
    }
    s.refresh_prior();
  }
}

void SqrtRls::update_in_one_pass() noexcept {
  // A large factor lives in L3 or memory, so its cost is the passes over it.
  // Everything a sample does to it is done row by row in one pass:
  //  * the sample's rotation of row i (forgetting folded in), then, when the
  //    kept-alive prior is due, the prior row's rotation of the same row:
  //    the sample's row has already left row i, and the prior's row reaches
  //    it after rows [k, i) took both rotations, exactly as in two passes;
  //  * once row i is final, its share of beta = L^T z (z the target column)
  //    and its target entry for the RSS suffix sums, while the row is in
  //    cache, instead of a pass over L and a strided walk of R afterwards.
  const std::size_t n = p_ + 1;
  const std::size_t width = givens::padded(n);
  bool prior_due = false;
  if (lambda_ < 1.0 && ++since_prior_ >= prior_period_) {
    since_prior_ = 0;
    prior_due = true;
  }
  const std::size_t first_prior = prior_due ? next_prior_row_ : n;
  if (prior_due) {
    prior_work_.setZero();
    prior_work_[static_cast<Eigen::Index>(first_prior)] = prior_weight_;
    if (track_inverse_) prior_work_inv_.setZero();
  }
  if (track_inverse_) std::fill(work_inv_.data(), work_inv_.data() + p_, 0.0);
  const bool with_coefficients = wald_block_ > 0;
  if (with_coefficients) coef_.setZero();
  double* beta = with_coefficients ? coef_.data() : nullptr;
  double* w = work_.data();
  double* prior = prior_work_.data();
  for (std::size_t i = 0; i < n; ++i) {
    if (i + 2 < n) prefetch_row(i + 2);
    double* r = r_.row(static_cast<Eigen::Index>(i)).data();
    const Rotation rot = rotate(r, w, i, width, sqrt_lambda_);
    const Rotation rot_prior = i >= first_prior ? rotate(r, prior, i, width, 1.0) : Rotation{};
    if (i < p_) {
      if (track_inverse_) {
        double* l = linv_.row(static_cast<Eigen::Index>(i)).data();
        rotate_inverse(l, work_inv_.data(), i + 1, rot, inv_sqrt_lambda_);
        if (i >= first_prior) rotate_inverse(l, prior_work_inv_.data(), i + 1, rot_prior, 1.0);
        if (with_coefficients) {
          const double z = r[p_];
          const std::size_t stop = givens::padded(i + 1);  // zeros past the diagonal
          for (std::size_t k = 0; k < stop; ++k) beta[k] += z * l[k];
        }
      }
    }
    rss_target_[static_cast<Eigen::Index>(i)] = r[p_];
  }
  downdate_block_covariances(1.0 / lambda_, work_inv_.data());
  if (prior_due) {
    downdate_block_covariances(1.0, prior_work_inv_.data());
    next_prior_row_ = (next_prior_row_ + 1) % p_;
  }
  if (wald_block_ > 0) {
    resync_block_covariance(next_resync_);
    next_resync_ = (next_resync_ + wald_block_) % p_;
  }
  double sum = 0.0;
  for (std::size_t i = n; i-- > 0;) {
    const double v = rss_target_[static_cast<Eigen::Index>(i)];
    sum += v * v;
    rss_tail_[static_cast<Eigen::Index>(i)] = sum;
  }
  rss_stamp_ = changes_;
  if (with_coefficients) coef_stamp_ = changes_;
}

void SqrtRls::refresh_prior() noexcept {
  if (lambda_ >= 1.0 || ++since_prior_ < prior_period_) return;
  // Keep the prior alive: one unit row every K samples, round robin,
  // weighted so that p of them add (1 - lambda) * delta * p K per direction.
  since_prior_ = 0;
  double* w = work_.data();
  std::fill(w, w + p_ + 1, 0.0);
  w[next_prior_row_] = prior_weight_;
  absorb(next_prior_row_, 1.0);
  next_prior_row_ = (next_prior_row_ + 1) % p_;
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
  return retriangularised_rss(scratch, rows, cols, count);
}

double SqrtRls::retriangularised_rss(Matrix& scratch, std::size_t rows, std::size_t cols, std::size_t count) noexcept {
  constexpr std::size_t kChunk = 64;
  for (std::size_t c = 0; c + 1 < cols; ++c) {
    const std::size_t last_row = std::min(rows - 1, c + count);
    double sigma = 0.0;  // squares below the diagonal
    for (std::size_t r = c + 1; r <= last_row; ++r) {
      const double v = scratch(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c));
      sigma += v * v;
    }
    if (sigma == 0.0) continue;
    double* pivot = scratch.row(static_cast<Eigen::Index>(c)).data();
    const double alpha = pivot[c];
    const double norm = std::sqrt(alpha * alpha + sigma);
    const double v0 = alpha >= 0.0 ? alpha + norm : alpha - norm;  // v = [v0, x below]
    const double tau = 2.0 / (v0 * v0 + sigma);
    // In chunks of columns: proj = tau v^T A[c:, chunk], then A -= v proj.
    for (std::size_t j0 = c + 1; j0 < cols; j0 += kChunk) {
      const std::size_t j1 = std::min(cols, j0 + kChunk);
      double proj[kChunk];
      for (std::size_t j = j0; j < j1; ++j) proj[j - j0] = v0 * pivot[j];
      for (std::size_t r = c + 1; r <= last_row; ++r) {
        const double* row = scratch.row(static_cast<Eigen::Index>(r)).data();
        const double vr = row[c];
        for (std::size_t j = j0; j < j1; ++j) proj[j - j0] += vr * row[j];
      }
      for (std::size_t j = j0; j < j1; ++j) proj[j - j0] *= tau;
      for (std::size_t j = j0; j < j1; ++j) pivot[j] -= v0 * proj[j - j0];
      for (std::size_t r = c + 1; r <= last_row; ++r) {
        double* row = scratch.row(static_cast<Eigen::Index>(r)).data();
        const double vr = row[c];
        for (std::size_t j = j0; j < j1; ++j) row[j] -= vr * proj[j - j0];
      }
    }
    for (std::size_t r = c + 1; r <= last_row; ++r) scratch(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) = 0.0;
    pivot[c] = alpha >= 0.0 ? -norm : norm;
  }
  double s = 0.0;
  for (std::size_t r = cols - 1; r < rows; ++r) {
    const double v = scratch(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(cols - 1));
    s += v * v;
  }
  return s;
}

double SqrtRls::rss_without_wald(std::size_t first, std::size_t count, Matrix& scratch) const noexcept {
  if (count == 0) return rss();
  if (first + count >= p_) return rss_prefix(first);  // trailing block: exact and free
  if (!track_inverse_) return rss_without(first, count, scratch);
  if (wald_block_ > 0 && count == wald_block_ && first % wald_block_ == 0) {
    // The block's covariance is tracked; beta_b from the shared L^T z.
    const double* beta = coefficients_from_inverse();
    double* g = scratch.row(static_cast<Eigen::Index>(count)).data();
    for (std::size_t a = 0; a < count; ++a) {
      g[a] = beta[first + a];
      const double* src = block_cov_.row(static_cast<Eigen::Index>(first + a)).data();
      std::copy(src, src + a + 1, scratch.row(static_cast<Eigen::Index>(a)).data());
    }
    const double quad = wald_quadratic(scratch, count);
    return quad >= 0.0 ? rss() + quad : rss_without(first, count, scratch);
  }
  // With M = L[first:p, b] (L = R^-T lower triangular, so rows above `first`
  // are zero in these columns) and z = R[first:p, target]:
  //   [(R^T R)^-1]_bb = M^T M = S,  beta_b = M^T z = g,
  //   RSS without b = RSS + g^T S^-1 g.
  // S in scratch rows [0, count), g in row `count`.
  double* g = scratch.row(static_cast<Eigen::Index>(count)).data();
  std::fill(g, g + count, 0.0);
  for (std::size_t a = 0; a < count; ++a) {
    double* srow = scratch.row(static_cast<Eigen::Index>(a)).data();
    std::fill(srow, srow + count, 0.0);
  }
  const auto target = static_cast<Eigen::Index>(p_);
  for (std::size_t k = first; k < p_; ++k) {
    const double* v = linv_.row(static_cast<Eigen::Index>(k)).data() + first;
    const double z = r_(static_cast<Eigen::Index>(k), target);
    const std::size_t len = std::min(count, k - first + 1);  // lower triangular
    for (std::size_t a = 0; a < len; ++a) {
      const double va = v[a];
      g[a] += va * z;
      double* srow = scratch.row(static_cast<Eigen::Index>(a)).data();
      for (std::size_t c = 0; c <= a; ++c) srow[c] += va * v[c];
    }
  }
  const double quad = wald_quadratic(scratch, count);
  return quad >= 0.0 ? rss() + quad : rss_without(first, count, scratch);
}

double SqrtRls::wald_quadratic(Matrix& scratch, std::size_t count) noexcept {
  // S in the lower triangle of scratch rows [0, count), g in row `count`.
  // Cholesky S = C C^T in place, forward solve C t = g; g^T S^-1 g = |t|^2.
  // -1 when S is not positive definite.
  double* g = scratch.row(static_cast<Eigen::Index>(count)).data();
  double quad = 0.0;
  for (std::size_t a = 0; a < count; ++a) {
    double* ca = scratch.row(static_cast<Eigen::Index>(a)).data();
    for (std::size_t b = 0; b <= a; ++b) {
      const double* cb = scratch.row(static_cast<Eigen::Index>(b)).data();
      double sum = ca[b];
      for (std::size_t k = 0; k < b; ++k) sum -= ca[k] * cb[k];
      if (b < a) {
        ca[b] = sum / cb[b];
      } else {
        if (!(sum > 0.0)) return -1.0;  // not positive definite
        ca[a] = std::sqrt(sum);
      }
    }
    double t = g[a];
    for (std::size_t k = 0; k < a; ++k) t -= ca[k] * g[k];
    g[a] = t / ca[a];
    quad += g[a] * g[a];
  }
  return quad;
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

void SqrtRls::solve_prefix_padded(std::size_t k, double* __restrict beta) const noexcept {
  // Column by column as solve_prefix (one product and one update on the
  // dependency chain per coefficient), with plain pointers: no alias checks
  // or strided-gather vector code, which cost more than they save on the
  // short prefixes the monitor solves every sample.
  const std::size_t stop = givens::padded(k);
  std::fill(beta + k, beta + stop, 0.0);
  const double* __restrict r = r_.data();
  const auto ld = static_cast<std::size_t>(r_.cols());
  for (std::size_t i = 0; i < k; ++i) beta[i] = r[i * ld + p_];
  for (std::size_t i = k; i-- > 0;) {
    const double* col = r + i;
    const double b = beta[i] * (1.0 / col[i * ld]);
    beta[i] = b;
    for (std::size_t row = 0; row < i; ++row) beta[row] -= col[row * ld] * b;
  }
}

}  // namespace mpm
