#include "core/ud_rls.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/givens.hpp"

namespace mpm {

UdRls::UdRls(std::size_t n_regressors, double forgetting, double regularization)
    : p_(n_regressors), lambda_(forgetting), delta_(regularization) {
  if (n_regressors == 0) throw std::invalid_argument("UdRls: need at least one regressor");
  if (!(forgetting > 0.0 && forgetting <= 1.0)) throw std::invalid_argument("UdRls: forgetting must be in (0, 1]");
  if (!(regularization > 0.0)) throw std::invalid_argument("UdRls: regularization must be > 0");
  prior_ = KeptAlivePrior(p_, lambda_, delta_);
  const auto n = static_cast<Eigen::Index>(p_ + 1);
  u_.resize(n, static_cast<Eigen::Index>(givens::padded(p_ + 1)));
  d_.resize(n);
  work_ = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(givens::padded(p_ + 1)));
  rss_tail_ = Eigen::VectorXd::Zero(n);
  reset();
}

void UdRls::reset() noexcept {
  // R = sqrt(delta) I on the regressors, nothing on the target: U = I,
  // D = delta (the target row's weight 0 until y is seen).
  u_.setZero();
  for (std::size_t i = 0; i <= p_; ++i) u_(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(i)) = 1.0;
  d_.setConstant(delta_);
  d_[static_cast<Eigen::Index>(p_)] = 0.0;
  prior_.reset();
  ++changes_;
}

void UdRls::absorb(std::size_t first, double lambda) noexcept {
  const std::size_t end = givens::padded(p_ + 1);
  double* b = work_.data();
  double w = work_weight_;
  ++changes_;
  for (std::size_t i = first; i <= p_; ++i)
    givens::rotate_sqrt_free(u_.row(static_cast<Eigen::Index>(i)).data(), d_[static_cast<Eigen::Index>(i)], b, w, i,
                             end, lambda);
}

void UdRls::update(const double* x, double y, double weight) noexcept {
  std::copy(x, x + p_, work_.data());
  work_[static_cast<Eigen::Index>(p_)] = y;
  work_weight_ = weight;
  UdRls* self = this;
  update_staged(&self, 1);
}

void UdRls::add_row(const double* x, double y, double weight) noexcept {
  std::copy(x, x + p_, work_.data());
  work_[static_cast<Eigen::Index>(p_)] = y;
  work_weight_ = weight;
  absorb(0, 1.0);
}

void UdRls::update_staged(UdRls* const* models, std::size_t count) noexcept {
  // Row i of every model, then row i + 1: their divisions overlap.
  std::size_t rows = 0;
  constexpr std::size_t kMaxTogether = 16;
  if (count > kMaxTogether) {
    for (std::size_t m = 0; m < count; m += kMaxTogether)
      update_staged(models + m, std::min(kMaxTogether, count - m));
    return;
  }
  double weights[kMaxTogether];
  for (std::size_t m = 0; m < count; ++m) {
    rows = std::max(rows, models[m]->p_ + 1);
    ++models[m]->changes_;
    weights[m] = models[m]->work_weight_;
  }
  for (std::size_t i = 0; i < rows; ++i)
    for (std::size_t m = 0; m < count; ++m) {
      UdRls& s = *models[m];
      if (i <= s.p_)
        givens::rotate_sqrt_free(s.u_.row(static_cast<Eigen::Index>(i)).data(), s.d_[static_cast<Eigen::Index>(i)],
                                 s.work_.data(), weights[m], i, givens::padded(s.p_ + 1), s.lambda_);
    }
  for (std::size_t m = 0; m < count; ++m) models[m]->refresh_prior();
}

void UdRls::refresh_prior() noexcept {
  if (const auto row = prior_.due(work_.data(), p_ + 1)) {
    work_weight_ = 1.0;
    absorb(*row, 1.0);
  }
}

double UdRls::rss_prefix(std::size_t k) const noexcept {
  if (rss_stamp_ != changes_) {
    const auto last = static_cast<Eigen::Index>(p_);
    double s = d_[last];
    rss_tail_[last] = s;
    for (std::size_t i = p_; i-- > 0;) {
      const auto ii = static_cast<Eigen::Index>(i);
      const double z = u_(ii, last);
      s += d_[ii] * (z * z);
      rss_tail_[ii] = s;
    }
    rss_stamp_ = changes_;
  }
  return rss_tail_[static_cast<Eigen::Index>(k)];
}

double UdRls::rss_without(std::size_t first, std::size_t count, Matrix& scratch) const noexcept {
  if (count == 0) return rss();
  if (first + count >= p_ + 1) return rss_prefix(first);  // dropping a trailing block
  const std::size_t rows = p_ + 1 - first;
  const std::size_t cols = p_ + 1 - first - count;
  for (std::size_t r = 0; r < rows; ++r) {
    const auto rr = static_cast<Eigen::Index>(first + r);
    const double scale = std::sqrt(d_[rr]);  // R = D^1/2 U
    double* dst = scratch.row(static_cast<Eigen::Index>(r)).data();
    const double* src = u_.row(rr).data() + first + count;
    for (std::size_t c = 0; c < cols; ++c) dst[c] = scale * src[c];
  }
  return retriangularised_rss(scratch, rows, cols, count);
}

void UdRls::solve_prefix(std::size_t k, Eigen::Ref<Eigen::VectorXd> out) const noexcept { solve(k, out.data()); }

void UdRls::solve_prefix_padded(std::size_t k, double* beta) const noexcept {
  std::fill(beta + k, beta + givens::padded(k), 0.0);
  solve(k, beta);
}

void UdRls::solve(std::size_t k, double* __restrict beta) const noexcept {
  // Back substitution U[0:k, 0:k] beta = z[0:k], column by column: one
  // product and one update per coefficient on the dependency chain, and no
  // division (unit diagonal).
  const double* __restrict u = u_.data();
  const auto ld = static_cast<std::size_t>(u_.cols());
  for (std::size_t i = 0; i < k; ++i) beta[i] = u[i * ld + p_];
  for (std::size_t i = k; i-- > 0;) {
    const double* col = u + i;
    const double b = beta[i];
    for (std::size_t row = 0; row < i; ++row) beta[row] -= col[row * ld] * b;
  }
}

UdRls::Matrix UdRls::factor() const {
  const auto n = static_cast<Eigen::Index>(p_ + 1);
  Matrix r = u_.leftCols(n);
  for (Eigen::Index i = 0; i < n; ++i) r.row(i) *= std::sqrt(d_[i]);
  return r;
}

}  // namespace mpm
