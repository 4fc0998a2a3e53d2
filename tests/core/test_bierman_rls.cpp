// Covariance-form UD RLS (BiermanRls) against the information-form factor
// (SqrtRls): its coefficients, RSS and Wald conditional RSS against the
// factor's back substitution, prefix sums and re-triangularisation. Its
// coefficients and RSS are recursions, so they are compared over long runs,
// with and without forgetting, with weighted rows.
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "core/bierman_rls.hpp"
#include "support/sqrt_rls.hpp"
#include "support/batch_qr.hpp"

namespace mpm {
namespace {

using test::DataGen;

double rel(double a, double b) { return std::abs(a - b) / std::abs(b); }

void expect_equal_to_sqrt_rls(double lambda, int samples, double tol, double regularization) {
  const std::size_t nb = 5, blocks = 6, p = nb * blocks;
  BiermanRls bierman(p, nb, lambda, regularization);
  SqrtRls sqrt_rls(p, lambda, regularization);
  DataGen gen(static_cast<int>(p));
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> weight(0.05, 2.0);
  Eigen::VectorXd x(static_cast<Eigen::Index>(p)), scaled(static_cast<Eigen::Index>(p));
  double y = 0;
  for (int k = 0; k < samples; ++k) {
    gen.next(x, y);
    const double w = weight(rng);
    bierman.update(x.data(), y, w);
    scaled = std::sqrt(w) * x;
    sqrt_rls.update(scaled.data(), std::sqrt(w) * y);
    if (k % 97 == 0) {  // rows added without forgetting, as NestedRls passes on its prior rows
      bierman.add_row(x.data(), 0.5 * y, 0.3);
      scaled = std::sqrt(0.3) * x;
      sqrt_rls.add_row(scaled.data(), std::sqrt(0.3) * 0.5 * y);
    }
  }
  EXPECT_LT(rel(bierman.rss(), sqrt_rls.rss()), tol);
  EXPECT_LT(rel(bierman.rss_empty(), sqrt_rls.rss_prefix(0)), tol);
  BiermanRls::Matrix scratch(static_cast<Eigen::Index>(p + 1), static_cast<Eigen::Index>(p + 1));
  SqrtRls::Matrix scratch_sq(static_cast<Eigen::Index>(p + 1), static_cast<Eigen::Index>(p + 1));
  for (std::size_t i = 0; i < blocks; ++i)
    EXPECT_LT(rel(bierman.rss_without_block(i, scratch), sqrt_rls.rss_without(i * nb, nb, scratch_sq)), tol) << i;
  Eigen::VectorXd beta(static_cast<Eigen::Index>(p));
  sqrt_rls.solve_prefix(p, beta);
  EXPECT_LT((bierman.coefficients() - beta).norm() / beta.norm(), tol);
  const Eigen::MatrixXd r = sqrt_rls.factor().topLeftCorner(static_cast<Eigen::Index>(p), static_cast<Eigen::Index>(p));
  const Eigen::MatrixXd info = r.transpose() * r;
  const Eigen::MatrixXd cov = info.inverse();
  EXPECT_LT((bierman.covariance() - cov).norm() / cov.norm(), tol);
}

// The monitor's prior is 1e-9 per regressor (P starts at 1e9 I): the
// covariance form must not lose the first samples to cancellation.
TEST(BiermanRls, EqualsSqrtRlsWithoutForgetting) {
  expect_equal_to_sqrt_rls(1.0, 200'000, 1e-8, 1e-6);
  expect_equal_to_sqrt_rls(1.0, 20'000, 1e-8, 1e-9);
}

TEST(BiermanRls, EqualsSqrtRlsWithForgettingOverALongRun) {
  expect_equal_to_sqrt_rls(0.999, 200'000, 1e-8, 1e-6);
  expect_equal_to_sqrt_rls(0.99, 20'000, 1e-8, 1e-9);
}

TEST(BiermanRls, StaysBoundedWithoutExcitation) {
  const std::size_t p = 6;
  BiermanRls rls(p, 3, 0.98, 1e-6);
  Eigen::VectorXd x = Eigen::VectorXd::Constant(static_cast<Eigen::Index>(p), 2.0);
  x[0] = 1.0;
  for (int k = 0; k < 10'000; ++k) rls.update(x.data(), 1.0 + 1e-3 * std::sin(k));
  const Eigen::MatrixXd cov = rls.covariance();
  ASSERT_TRUE(cov.allFinite());
  EXPECT_LT(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(cov).eigenvalues().maxCoeff(), 4.0 / 1e-6);
  EXPECT_TRUE(rls.coefficients().allFinite());
  BiermanRls::Matrix scratch(4, 3);
  EXPECT_TRUE(std::isfinite(rls.rss_without_block(0, scratch)));
}

TEST(BiermanRls, RejectsInvalidSettings) {
  EXPECT_THROW(BiermanRls(0, 1, 0.99), std::invalid_argument);
  EXPECT_THROW(BiermanRls(10, 3, 0.99), std::invalid_argument);  // whole blocks only
  EXPECT_THROW(BiermanRls(9, 3, 0.0), std::invalid_argument);
  EXPECT_THROW(BiermanRls(9, 3, 0.99, 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace mpm
