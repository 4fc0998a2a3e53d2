#include "core/bierman_rls.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/givens.hpp"

namespace mpm {

using givens::kLanes;
using givens::Lanes;
using givens::load;
using givens::padded;
using givens::store;

namespace {

// g^T S^-1 g for the Wald identity: S in the lower triangle of scratch rows
// [0, count), g in row `count`; -1 if S is not positive definite.
double wald_quadratic(BiermanRls::Matrix& scratch, std::size_t count) noexcept {
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

}  // namespace

BiermanRls::BiermanRls(std::size_t n_regressors, std::size_t block, double forgetting, double regularization)
    : p_(n_regressors), nb_(block), lambda_(forgetting), delta_(regularization) {
  if (n_regressors == 0 || block == 0 || n_regressors % block != 0)
    throw std::invalid_argument("BiermanRls: need whole blocks of at least one regressor");
  if (!(forgetting > 0.0 && forgetting <= 1.0)) throw std::invalid_argument("BiermanRls: forgetting must be in (0, 1]");
  if (!(regularization > 0.0)) throw std::invalid_argument("BiermanRls: regularization must be > 0");
  prior_ = KeptAlivePrior(p_, lambda_, delta_);
  column_.resize(static_cast<Eigen::Index>(p_ + 1));
  std::size_t offset = 0;
  for (std::size_t j = 0; j <= p_; ++j) {
    column_[static_cast<Eigen::Index>(j)] = offset;
    if (j < p_) offset += padded(j);
  }
  u_.resize(static_cast<Eigen::Index>(offset));
  d_.resize(static_cast<Eigen::Index>(p_));
  theta_.resize(static_cast<Eigen::Index>(p_));
  h_ = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(padded(p_ + 1)));
  gain_ = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(padded(p_)));
  block_cov_.resize(static_cast<Eigen::Index>(p_), static_cast<Eigen::Index>(nb_));
  reset();
}

void BiermanRls::reset() noexcept {
  // P = I / delta: U = I (nothing stored above the diagonal), D = 1 / delta.
  u_.setZero();
  d_.setConstant(1.0 / delta_);
  theta_.setZero();
  block_cov_.setZero();
  for (std::size_t i = 0; i < p_; ++i)
    block_cov_(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(i % nb_)) = 1.0 / delta_;
  rss_ = 0.0;
  energy_ = 0.0;
  prior_.reset();
  next_resync_ = 0;
}

void BiermanRls::update(const double* x, double y, double weight) noexcept {
  std::copy(x, x + p_, h_.data());
  h_[static_cast<Eigen::Index>(p_)] = y;
  staged_weight_ = weight;
  update_staged();
}

void BiermanRls::update_staged() noexcept {
  absorb(staged_weight_, lambda_);
  // Rounding in the downdates is not self-correcting (each grows by
  // 1 / lambda): one block a sample is recomputed, so each is exact again
  // every p / nb samples.
  block_covariance_from_factor(next_resync_, block_cov_.row(static_cast<Eigen::Index>(next_resync_)).data(), nb_);
  next_resync_ = (next_resync_ + nb_) % p_;
  refresh_prior();
}

void BiermanRls::add_row(const double* x, double y, double weight) noexcept {
  std::copy(x, x + p_, h_.data());
  h_[static_cast<Eigen::Index>(p_)] = y;
  absorb(weight, 1.0);
}

void BiermanRls::refresh_prior() noexcept {
  if (const auto row = prior_.due(h_.data(), p_ + 1)) absorb(1.0, 1.0, *row);
}

void BiermanRls::absorb(double weight, double lambda, std::size_t first) noexcept {
  const double growth = 1.0 / lambda;
  double* __restrict h = h_.data();
  const double y = h[p_];
  std::fill(h + p_, h + h_.size(), 0.0);  // whole lanes of x only from here on
  if (!(weight > 0.0)) {  // no information: the past is only forgotten
    d_ *= growth;
    block_cov_ *= growth;
    rss_ *= lambda;
    energy_ *= lambda;
    return;
  }
  double* __restrict u = u_.data();
  double* __restrict d = d_.data();
  double* __restrict gain = gain_.data();
  double* __restrict theta = theta_.data();
  // A priori error, with the coefficients before this row.
  double e = y;
  for (std::size_t i = 0; i < p_; ++i) e -= theta[i] * h[i];
  // Bierman's update with measurement variance lambda / weight, column by
  // column: f_j = (U^T h)_j from column j's old values, then the column.
  // gain ends as P h (P before this row), alpha as lambda / weight + h^T P h.
  std::fill(gain, gain + gain_.size(), 0.0);
  double alpha = lambda / weight;
  if (lambda != 1.0) first = 0;  // forgetting touches every d_j
  for (std::size_t j = first; j < p_; ++j) {
    double* col = u + column_[static_cast<Eigen::Index>(j)];
    const std::size_t len = padded(j);  // rows [j, len) are zero padding, as gain is there
    // Four partial sums: one would make the column wait on the adder's
    // latency, four times over.
    Lanes acc0 = {}, acc1 = {}, acc2 = {}, acc3 = {};
    std::size_t i = 0;
    for (; i + 4 * kLanes <= len; i += 4 * kLanes) {
      acc0 += load(col + i) * load(h + i);
      acc1 += load(col + i + kLanes) * load(h + i + kLanes);
      acc2 += load(col + i + 2 * kLanes) * load(h + i + 2 * kLanes);
      acc3 += load(col + i + 3 * kLanes) * load(h + i + 3 * kLanes);
    }
    for (; i < len; i += kLanes) acc0 += load(col + i) * load(h + i);
    const double f = h[j] + givens::sum((acc0 + acc1) + (acc2 + acc3));
    const double g = d[j] * f;
    const double alpha_next = alpha + f * g;
    d[j] *= alpha / (alpha_next * lambda);
    const double pj = -f / alpha;
    for (std::size_t r = 0; r < len; r += kLanes) {
      const Lanes uo = load(col + r);
      const Lanes gi = load(gain + r);
      store(col + r, uo + gi * pj);
      store(gain + r, gi + uo * g);
    }
    gain[j] = g;
    alpha = alpha_next;
  }
  const double k = e / alpha;
  for (std::size_t i = 0; i < p_; ++i) theta[i] += gain[i] * k;
  rss_ = lambda * (rss_ + e * k);
  energy_ = lambda * energy_ + weight * y * y;
  // [P]_bb' = ([P]_bb - gain_b gain_b^T / alpha) / lambda, lower triangles.
  const double shrink = growth / alpha;
  for (std::size_t b0 = 0; b0 < p_; b0 += nb_)
    for (std::size_t r = 0; r < nb_; ++r) {
      double* srow = block_cov_.row(static_cast<Eigen::Index>(b0 + r)).data();
      const double gr = shrink * gain[b0 + r];
      for (std::size_t c = 0; c <= r; ++c) srow[c] = growth * srow[c] - gr * gain[b0 + c];
    }
}

void BiermanRls::block_covariance_from_factor(std::size_t b0, double* out, std::size_t ld) const noexcept {
  // [P]_bb = sum_k d_k U[b, k] U[b, k]^T over the columns k >= b0 (U is
  // upper triangular: rows of b below k are zero; U_kk = 1 is not stored).
  for (std::size_t r = 0; r < nb_; ++r) std::fill(out + r * ld, out + r * ld + nb_, 0.0);
  for (std::size_t k = b0; k < p_; ++k) {
    const double* v = u_.data() + column_[static_cast<Eigen::Index>(k)] + b0;
    const std::size_t stored = std::min(nb_, k - b0);  // rows b0 .. k-1 of this block
    const double dk = d_[static_cast<Eigen::Index>(k)];
    for (std::size_t a = 0; a < stored; ++a) {
      double* row = out + a * ld;
      const double va = dk * v[a];
      for (std::size_t c = 0; c <= a; ++c) row[c] += va * v[c];
    }
    if (stored < nb_) {  // k inside the block: its row has U_kk = 1
      double* row = out + stored * ld;
      for (std::size_t c = 0; c < stored; ++c) row[c] += dk * v[c];
      row[stored] += dk;
    }
  }
}

double BiermanRls::rss_without_block(std::size_t i, Matrix& scratch) const noexcept {
  const std::size_t b0 = i * nb_;
  const auto fill_g = [&] {
    double* g = scratch.row(static_cast<Eigen::Index>(nb_)).data();
    for (std::size_t a = 0; a < nb_; ++a) g[a] = theta_[static_cast<Eigen::Index>(b0 + a)];
  };
  for (std::size_t a = 0; a < nb_; ++a) {
    const double* src = block_cov_.row(static_cast<Eigen::Index>(b0 + a)).data();
    std::copy(src, src + a + 1, scratch.row(static_cast<Eigen::Index>(a)).data());
  }
  fill_g();
  double quad = wald_quadratic(scratch, nb_);
  if (quad < 0.0) {  // the tracked block lost definiteness to rounding: from the factor
    block_covariance_from_factor(b0, scratch.data(), static_cast<std::size_t>(scratch.cols()));
    fill_g();
    quad = wald_quadratic(scratch, nb_);
  }
  return quad >= 0.0 ? rss_ + quad : NAN;
}

Eigen::MatrixXd BiermanRls::covariance() const {
  const auto n = static_cast<Eigen::Index>(p_);
  Eigen::MatrixXd u = Eigen::MatrixXd::Identity(n, n);
  for (std::size_t j = 0; j < p_; ++j)
    for (std::size_t i = 0; i < j; ++i)
      u(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = u_[static_cast<Eigen::Index>(column_[static_cast<Eigen::Index>(j)] + i)];
  return u * d_.asDiagonal() * u.transpose();
}

double BiermanRls::covariance_quadratic(const double* s) const noexcept {
  // s^T U D U^T s = sum_j D_j (s_j + sum_{i<j} U_ij s_i)^2.
  double q = 0.0;
  for (std::size_t j = 0; j < p_; ++j) {
    const double* col = u_.data() + column_[static_cast<Eigen::Index>(j)];
    double v = s[j];
    for (std::size_t i = 0; i < j; ++i) v += col[i] * s[i];
    q += d_[static_cast<Eigen::Index>(j)] * v * v;
  }
  return q;
}

void BiermanRls::covariance_into(double* out, std::size_t ld) const noexcept {
  const auto unit = [&](std::size_t i, std::size_t j) {
    return i == j ? 1.0 : i < j ? u_[static_cast<Eigen::Index>(column_[static_cast<Eigen::Index>(j)] + i)] : 0.0;
  };
  for (std::size_t a = 0; a < p_; ++a)
    for (std::size_t b = a; b < p_; ++b) {
      double v = 0.0;
      for (std::size_t j = b; j < p_; ++j) v += unit(a, j) * d_[static_cast<Eigen::Index>(j)] * unit(b, j);
      out[a + b * ld] = v;
      out[b + a * ld] = v;
    }
}

}  // namespace mpm
