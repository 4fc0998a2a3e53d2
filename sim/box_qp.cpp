#include "sim/box_qp.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace mpm::sim {
namespace {

// In-place Cholesky of the leading k x k block of a (lower triangle used).
bool cholesky(Eigen::MatrixXd& a, std::size_t k) noexcept {
  for (std::size_t j = 0; j < k; ++j) {
    const auto jj = static_cast<Eigen::Index>(j);
    double d = a(jj, jj);
    for (std::size_t p = 0; p < j; ++p) d -= a(jj, static_cast<Eigen::Index>(p)) * a(jj, static_cast<Eigen::Index>(p));
    if (!(d > 0.0)) return false;
    d = std::sqrt(d);
    a(jj, jj) = d;
    for (std::size_t i = j + 1; i < k; ++i) {
      const auto ii = static_cast<Eigen::Index>(i);
      double s = a(ii, jj);
      for (std::size_t p = 0; p < j; ++p) s -= a(ii, static_cast<Eigen::Index>(p)) * a(jj, static_cast<Eigen::Index>(p));
      a(ii, jj) = s / d;
    }
  }
  return true;
}

// Solves L L' x = b for the leading k x k block, b overwritten by x.
void cholesky_solve(const Eigen::MatrixXd& l, std::size_t k, Eigen::VectorXd& b) noexcept {
  for (std::size_t i = 0; i < k; ++i) {
    const auto ii = static_cast<Eigen::Index>(i);
    double s = b(ii);
    for (std::size_t p = 0; p < i; ++p) s -= l(ii, static_cast<Eigen::Index>(p)) * b(static_cast<Eigen::Index>(p));
    b(ii) = s / l(ii, ii);
  }
  for (std::size_t i = k; i-- > 0;) {
    const auto ii = static_cast<Eigen::Index>(i);
    double s = b(ii);
    for (std::size_t p = i + 1; p < k; ++p) s -= l(static_cast<Eigen::Index>(p), ii) * b(static_cast<Eigen::Index>(p));
    b(ii) = s / l(ii, ii);
  }
}

}  // namespace

BoxQp::BoxQp(const Eigen::MatrixXd& h, int max_active_set_iterations, int max_gradient_iterations)
    : h_(h), max_active_set_iterations_(max_active_set_iterations), max_gradient_iterations_(max_gradient_iterations) {
  if (h.rows() != h.cols() || h.rows() == 0) throw std::invalid_argument("box QP: H must be square and non-empty");
  if (!h.isApprox(h.transpose(), 1e-10)) throw std::invalid_argument("box QP: H must be symmetric");
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(h, Eigen::EigenvaluesOnly);
  if (!(eig.eigenvalues()(0) > 0.0)) throw std::invalid_argument("box QP: H must be positive definite");
  lipschitz_ = eig.eigenvalues()(h.rows() - 1);
  const auto n = h.rows();
  state_.assign(static_cast<std::size_t>(n), 0);
  free_.assign(static_cast<std::size_t>(n), 0);
  chol_.resize(n, n);
  rhs_.resize(n);
  grad_.resize(n);
  y_.resize(n);
  v_prev_.resize(n);
}

// Free variables: H_FF v_F = -g_F - H_FA v_A, with the bound ones already in v.
bool BoxQp::solve_free(const Eigen::VectorXd& g, Eigen::VectorXd& v) noexcept {
  std::size_t k = 0;
  for (std::size_t i = 0; i < state_.size(); ++i)
    if (state_[i] == 0) free_[k++] = i;
  for (std::size_t a = 0; a < k; ++a) {
    const auto ia = static_cast<Eigen::Index>(free_[a]);
    double s = -g(ia);
    for (std::size_t i = 0; i < state_.size(); ++i)
      if (state_[i] != 0) s -= h_(ia, static_cast<Eigen::Index>(i)) * v(static_cast<Eigen::Index>(i));
    rhs_(static_cast<Eigen::Index>(a)) = s;
    for (std::size_t b = 0; b <= a; ++b)
      chol_(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b)) = h_(ia, static_cast<Eigen::Index>(free_[b]));
  }
  if (!cholesky(chol_, k)) return false;
  cholesky_solve(chol_, k, rhs_);
  for (std::size_t a = 0; a < k; ++a) v(static_cast<Eigen::Index>(free_[a])) = rhs_(static_cast<Eigen::Index>(a));
  return true;
}

// Binds free variables outside their box; frees bound ones whose gradient
// points into the box (a multiplier of the wrong sign). True if unchanged.
bool BoxQp::update_active_set(const Eigen::VectorXd& lo, const Eigen::VectorXd& hi,
                              const Eigen::VectorXd& v) noexcept {
  bool unchanged = true;
  for (std::size_t i = 0; i < state_.size(); ++i) {
    const auto ii = static_cast<Eigen::Index>(i);
    int next = state_[i];
    if (state_[i] == 0) {
      next = v(ii) < lo(ii) ? -1 : (v(ii) > hi(ii) ? 1 : 0);
    } else if (state_[i] < 0 && grad_(ii) < 0.0) {
      next = 0;
    } else if (state_[i] > 0 && grad_(ii) > 0.0) {
      next = 0;
    }
    unchanged = unchanged && next == state_[i];
    state_[i] = next;
  }
  return unchanged;
}

BoxQpResult BoxQp::solve(const Eigen::VectorXd& g, const Eigen::VectorXd& lo, const Eigen::VectorXd& hi,
                         Eigen::VectorXd& v) noexcept {
  BoxQpResult result;
  for (std::size_t i = 0; i < state_.size(); ++i) {
    const auto ii = static_cast<Eigen::Index>(i);
    state_[i] = v(ii) < lo(ii) ? -1 : (v(ii) > hi(ii) ? 1 : 0);
  }
  while (result.active_set_iterations < max_active_set_iterations_) {
    ++result.active_set_iterations;
    for (std::size_t i = 0; i < state_.size(); ++i) {
      const auto ii = static_cast<Eigen::Index>(i);
      if (state_[i] != 0) v(ii) = state_[i] < 0 ? lo(ii) : hi(ii);
    }
    if (!solve_free(g, v)) break;
    grad_.noalias() = h_ * v;
    grad_ += g;
    if (update_active_set(lo, hi, v)) {
      result.converged = true;
      return result;
    }
  }
  result.converged = projected_gradient(g, lo, hi, v, result.gradient_iterations);
  return result;
}

// FISTA with a monotone restart, from the clamped current point.
bool BoxQp::projected_gradient(const Eigen::VectorXd& g, const Eigen::VectorXd& lo, const Eigen::VectorXd& hi,
                               Eigen::VectorXd& v, int& iterations) noexcept {
  v = v.cwiseMax(lo).cwiseMin(hi);
  y_ = v;
  double t = 1.0;
  const double step = 1.0 / lipschitz_;
  const double tol = 1e-10 * (1.0 + g.cwiseAbs().maxCoeff());
  for (iterations = 0; iterations < max_gradient_iterations_;) {
    ++iterations;
    grad_.noalias() = h_ * y_;
    grad_ += g;
    v_prev_ = v;
    v = (y_ - step * grad_).cwiseMax(lo).cwiseMin(hi);
    const double moved = (v - v_prev_).cwiseAbs().maxCoeff();
    if (moved * lipschitz_ < tol) return true;
    const double t_next = 0.5 * (1.0 + std::sqrt(1.0 + 4.0 * t * t));
    // Restart the momentum when it points uphill.
    if ((v - v_prev_).dot(grad_) > 0.0) {
      t = 1.0;
      y_ = v;
      continue;
    }
    y_ = v + ((t - 1.0) / t_next) * (v - v_prev_);
    t = t_next;
  }
  return false;
}

}  // namespace mpm::sim
