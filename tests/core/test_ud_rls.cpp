// Square-root-free RLS (UdRls) against SqrtRls, the factor it must equal
// (R = D^1/2 U), and what only it does: weighted rows, an exact unit
// diagonal. Against batch least squares: test_rls_factors.cpp.
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "support/sqrt_rls.hpp"
#include "core/ud_rls.hpp"
#include "support/batch_qr.hpp"

namespace mpm {
namespace {

using test::DataGen;
using test::kDelta;

double rel(double a, double b) { return std::abs(a - b) / std::abs(b); }

// The factor itself, R = D^1/2 U, is SqrtRls's (a triangular factor with a
// positive diagonal is unique) over a long run with forgetting, the kept-alive
// prior included; and weighted rows equal rows scaled by sqrt(weight).
TEST(UdRls, FactorEqualsSqrtRlsOverALongRunWithWeights) {
  const int p = 31;
  const double lambda = 0.999;
  UdRls ud(p, lambda, 1e-6);
  SqrtRls sq(p, lambda, 1e-6);
  DataGen gen(p);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> weight(0.01, 2.0);
  Eigen::VectorXd x(p), scaled(p);
  double y = 0;
  for (int k = 0; k < 200'000; ++k) {
    gen.next(x, y);
    const double w = weight(rng);
    ud.update(x.data(), y, w);
    scaled = std::sqrt(w) * x;
    sq.update(scaled.data(), std::sqrt(w) * y);
  }
  const UdRls::Matrix r_ud = ud.factor();
  const Eigen::MatrixXd r_sq = sq.factor();
  EXPECT_LT((r_ud - r_sq).norm() / r_sq.norm(), 1e-9);
  for (std::size_t k = 0; k <= p; ++k) EXPECT_LT(rel(ud.rss_prefix(k), sq.rss_prefix(k)), 1e-9) << k;
  Eigen::VectorXd b_ud(p), b_sq(p);
  ud.solve_prefix(p, b_ud);
  sq.solve_prefix(p, b_sq);
  EXPECT_LT((b_ud - b_sq).norm() / b_sq.norm(), 1e-8);
  // The unit diagonal and the zeros below it are exact, not rounded: the
  // solves and the rotations' whole-lane blocks rely on them.
  const auto u = ud.unit_factor();
  for (Eigen::Index i = 0; i <= p; ++i) {
    EXPECT_EQ(u(i, i), 1.0) << i;
    for (Eigen::Index j = 0; j < i; ++j) EXPECT_EQ(u(i, j), 0.0) << i << "," << j;
  }
}

TEST(UdRls, RssWithoutEveryBlockEqualsSqrtRls) {
  const int p = 12;
  UdRls ud(p, 0.995, kDelta);
  SqrtRls sq(p, 0.995, kDelta);
  DataGen gen(p);
  Eigen::VectorXd x(p);
  double y = 0;
  for (int k = 0; k < 3000; ++k) {
    gen.next(x, y);
    ud.update(x.data(), y);
    sq.update(x.data(), y);
  }
  UdRls::Matrix scratch(p + 1, p + 1);
  SqrtRls::Matrix scratch_sq(p + 1, p + 1);
  for (int first = 0; first < p; ++first)
    for (int count = 1; first + count <= p; ++count) {
      const auto f = static_cast<std::size_t>(first), c = static_cast<std::size_t>(count);
      EXPECT_NEAR(ud.rss_without(f, c, scratch) / sq.rss_without(f, c, scratch_sq), 1.0, 1e-10) << first << "+" << count;
    }
}

TEST(UdRls, LockstepUpdateEqualsUpdatesAlone) {
  // update_staged interleaves the models' rows; each must end bit for bit as
  // if updated alone (the monitor's parts rely on it).
  const std::size_t sizes[] = {3, 10, 21};
  std::vector<UdRls> alone, together;
  for (std::size_t p : sizes) {
    alone.emplace_back(p, 0.99, 1e-6);
    together.emplace_back(p, 0.99, 1e-6);
  }
  std::mt19937_64 rng(5);
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<double> x(22);
  for (int k = 0; k < 5000; ++k) {
    UdRls* staged[3];
    for (std::size_t m = 0; m < 3; ++m) {
      for (double& v : x) v = n(rng);
      const double w = 0.5 + 0.25 * static_cast<double>(m);
      alone[m].update(x.data(), x[sizes[m]], w);
      std::copy(x.begin(), x.begin() + static_cast<std::ptrdiff_t>(sizes[m] + 1), together[m].staged_row());
      together[m].stage_weight(w);
      staged[m] = &together[m];
    }
    UdRls::update_staged(staged, 3);
  }
  for (std::size_t m = 0; m < 3; ++m) {
    EXPECT_EQ(alone[m].rss(), together[m].rss()) << m;
    EXPECT_EQ(alone[m].factor(), together[m].factor()) << m;
  }
}

TEST(UdRls, ZeroWeightRowsChangeNothing) {
  UdRls a(4, 1.0, kDelta), b(4, 1.0, kDelta);
  const double x[] = {1.0, 0.5, -0.25, 2.0};
  a.update(x, 1.5);
  b.update(x, 1.5);
  b.update(x, 7.0, 0.0);  // weight 0: no information, no NaN
  EXPECT_EQ(a.factor(), b.factor());
  EXPECT_TRUE(std::isfinite(b.rss()));
}

TEST(UdRls, RejectsInvalidSettings) {
  EXPECT_THROW(UdRls(0, 0.99), std::invalid_argument);
  EXPECT_THROW(UdRls(3, 0.0), std::invalid_argument);
  EXPECT_THROW(UdRls(3, 1.01), std::invalid_argument);
  EXPECT_THROW(UdRls(3, 0.99, 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace mpm
