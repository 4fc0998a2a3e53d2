// The bound-constrained QP behind the MPC input limits, checked against
// enumeration of every active set on small random problems.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "sim/box_qp.hpp"

namespace mpm::sim {
namespace {

struct Problem {
  Eigen::MatrixXd h;
  Eigen::VectorXd g, lo, hi;
};

Problem random_problem(std::mt19937_64& rng, int n, double condition) {
  std::normal_distribution<double> n01;
  Eigen::MatrixXd a(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) a(i, j) = n01(rng);
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(a);
  const Eigen::MatrixXd q = qr.householderQ();
  Eigen::VectorXd eig(n);
  for (int i = 0; i < n; ++i) eig(i) = std::pow(condition, static_cast<double>(i) / (n - 1));
  Problem p;
  p.h = q * eig.asDiagonal() * q.transpose();
  p.h = 0.5 * (p.h + p.h.transpose());
  p.g.resize(n);
  p.lo.resize(n);
  p.hi.resize(n);
  for (int i = 0; i < n; ++i) {
    p.g(i) = 3.0 * n01(rng);
    p.lo(i) = -0.5 - std::abs(n01(rng));
    p.hi(i) = 0.5 + std::abs(n01(rng));
  }
  p.lo(0) = -std::numeric_limits<double>::infinity();  // one side unbounded
  return p;
}

// The KKT point found by trying every assignment lower/upper/free.
Eigen::VectorXd enumerate(const Problem& p) {
  const int n = static_cast<int>(p.g.size());
  int combos = 1;
  for (int i = 0; i < n; ++i) combos *= 3;
  for (int c = 0; c < combos; ++c) {
    Eigen::VectorXd v = Eigen::VectorXd::Zero(n);
    Eigen::VectorXi state(n), free(n);  // free(0 .. k-1): the free variables
    for (int i = 0, code = c; i < n; ++i, code /= 3) state(i) = code % 3 - 1;
    bool possible = true;
    int k = 0;
    for (int i = 0; i < n; ++i) {
      if (state(i) == 0) free(k++) = i;
      else v(i) = state(i) < 0 ? p.lo(i) : p.hi(i);
      if (!std::isfinite(v(i))) possible = false;
    }
    if (!possible) continue;
    Eigen::MatrixXd hf(k, k);
    Eigen::VectorXd rhs(k);
    for (int a = 0; a < k; ++a) {
      rhs(a) = -p.g(free(a));
      for (int i = 0; i < n; ++i)
        if (state(i) != 0) rhs(a) -= p.h(free(a), i) * v(i);
      for (int b = 0; b < k; ++b) hf(a, b) = p.h(free(a), free(b));
    }
    const Eigen::VectorXd vf = hf.ldlt().solve(rhs);
    for (int a = 0; a < k; ++a) v(free(a)) = vf(a);
    const Eigen::VectorXd grad = p.h * v + p.g;
    bool kkt = true;
    for (int i = 0; i < n; ++i) {
      if (state(i) == 0) kkt = kkt && v(i) >= p.lo(i) - 1e-12 && v(i) <= p.hi(i) + 1e-12;
      if (state(i) < 0) kkt = kkt && grad(i) >= -1e-10;
      if (state(i) > 0) kkt = kkt && grad(i) <= 1e-10;
    }
    if (kkt) return v;
  }
  ADD_FAILURE() << "no KKT point found by enumeration";
  return Eigen::VectorXd::Zero(n);
}

Eigen::VectorXd unconstrained(const Problem& p) { return p.h.llt().solve(-p.g); }

TEST(BoxQp, MatchesEnumerationOfActiveSets) {
  std::mt19937_64 rng(11);
  int constrained = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const Problem p = random_problem(rng, 6, trial % 2 ? 1e4 : 10.0);
    BoxQp qp(p.h);
    Eigen::VectorXd v = unconstrained(p);
    const bool inside = ((v.array() >= p.lo.array()) && (v.array() <= p.hi.array())).all();
    constrained += inside ? 0 : 1;
    const BoxQpResult r = qp.solve(p.g, p.lo, p.hi, v);
    EXPECT_TRUE(r.converged);
    const Eigen::VectorXd expected = enumerate(p);
    EXPECT_LT((v - expected).cwiseAbs().maxCoeff(), 1e-8) << "trial " << trial;
  }
  EXPECT_GT(constrained, 30);  // the test exercised the bounds
}

TEST(BoxQp, UnconstrainedOptimumInsideTheBoxIsReturnedAsIs) {
  std::mt19937_64 rng(5);
  Problem p = random_problem(rng, 5, 100.0);
  p.lo.setConstant(-1e6);
  p.hi.setConstant(1e6);
  BoxQp qp(p.h);
  Eigen::VectorXd v = unconstrained(p);
  const Eigen::VectorXd expected = v;
  const BoxQpResult r = qp.solve(p.g, p.lo, p.hi, v);
  EXPECT_EQ(r.active_set_iterations, 1);
  EXPECT_LT((v - expected).cwiseAbs().maxCoeff(), 1e-10);
}

TEST(BoxQp, GradientFallbackReachesTheSameSolution) {
  std::mt19937_64 rng(23);
  for (int trial = 0; trial < 10; ++trial) {
    const Problem p = random_problem(rng, 6, 50.0);
    BoxQp qp(p.h, /*max_active_set_iterations=*/0, /*max_gradient_iterations=*/100000);
    Eigen::VectorXd v = unconstrained(p);
    const BoxQpResult r = qp.solve(p.g, p.lo, p.hi, v);
    EXPECT_GT(r.gradient_iterations, 0);
    EXPECT_TRUE(r.converged);
    EXPECT_LT((v - enumerate(p)).cwiseAbs().maxCoeff(), 1e-6) << "trial " << trial;
  }
}

TEST(BoxQp, RejectsAnIndefiniteHessian) {
  Eigen::MatrixXd h(2, 2);
  h << 1, 2, 2, 1;
  EXPECT_THROW(BoxQp{h}, std::invalid_argument);
}

}  // namespace
}  // namespace mpm::sim
