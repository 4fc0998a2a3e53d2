// What every recursive least-squares factor of the core (SqrtRls, UdRls)
// must do, against an independent batch least-squares reference (Householder
// QR over the stacked data), with and without forgetting.
#include <cmath>

#include <gtest/gtest.h>

#include "support/sqrt_rls.hpp"
#include "core/ud_rls.hpp"
#include "support/batch_qr.hpp"

namespace mpm {
namespace {

using test::BatchQr;
using test::DataGen;
using test::feed;
using test::kDelta;
using test::range_except;

template <typename Factor>
class RecursiveFactor : public ::testing::Test {};
using Factors = ::testing::Types<SqrtRls, UdRls>;
TYPED_TEST_SUITE(RecursiveFactor, Factors);

TYPED_TEST(RecursiveFactor, EqualsBatchAfterAMillionSamples) {
  const int p = 7;
  TypeParam rls(p, 1.0, kDelta);
  BatchQr batch(p);
  DataGen gen(p);
  Eigen::MatrixXd rows(20'000, p + 1);
  for (int b = 0; b < 50; ++b) {  // a million samples, the batch fed a block at a time
    feed(rls, gen, rows);
    batch.add_block(rows);
  }
  const auto rel = [](double a, double b) { return std::abs(a - b) / std::abs(b); };
  EXPECT_LT(rel(rls.rss(), batch.rss(range_except(p, p, 0))), 1e-8);
  for (int k = 1; k <= p; ++k) EXPECT_LT(rel(rls.rss_prefix(static_cast<std::size_t>(k)), batch.rss(range_except(k, k, 0))), 1e-8) << k;
  typename TypeParam::Matrix scratch(p + 1, p + 1);
  EXPECT_LT(rel(rls.rss_without(2, 3, scratch), batch.rss(range_except(p, 2, 3))), 1e-8);
  Eigen::VectorXd beta(p);
  rls.solve_prefix(p, beta);
  const Eigen::VectorXd ref = batch.beta();
  EXPECT_LT((beta - ref).norm() / ref.norm(), 1e-8);
}

TYPED_TEST(RecursiveFactor, ForgettingEqualsWeightedBatch) {
  const int p = 5;
  const double lambda = 0.99;
  TypeParam rls(p, lambda, kDelta);
  DataGen gen(p);
  const int n = 2000;
  Eigen::MatrixXd rows(n, p + 1);
  feed(rls, gen, rows);
  for (int k = 0; k < n; ++k) rows.row(k) *= std::sqrt(std::pow(lambda, n - 1 - k));
  BatchQr batch(p);  // its prior is ~delta (the kept-alive prior is of the same size)
  batch.add_block(rows);
  EXPECT_NEAR(rls.rss() / batch.rss(range_except(p, p, 0)), 1.0, 1e-9);
  EXPECT_NEAR(rls.rss_prefix(2) / batch.rss(range_except(2, 2, 0)), 1.0, 1e-9);
}

// The conditional RSS by re-triangularisation on every block, against batch
// least squares on every subset.
TYPED_TEST(RecursiveFactor, RssWithoutEveryBlockMatchesBatchOnSubsets) {
  const int p = 12;
  TypeParam rls(p, 1.0, kDelta);
  BatchQr batch(p);
  DataGen gen(p);
  Eigen::MatrixXd rows(3000, p + 1);
  feed(rls, gen, rows);
  batch.add_block(rows);
  typename TypeParam::Matrix scratch(p + 1, p + 1);
  for (int first = 0; first < p; ++first)
    for (int count = 1; first + count <= p; ++count) {
      const double ref = batch.rss(range_except(p, first, count));
      EXPECT_NEAR(rls.rss_without(static_cast<std::size_t>(first), static_cast<std::size_t>(count), scratch) / ref, 1.0, 1e-10)
          << first << "+" << count;
    }
}

TYPED_TEST(RecursiveFactor, StaysBoundedWithoutExcitation) {
  // Inputs constant for 10^4 samples with forgetting: the information in the
  // unexcited directions decays; the kept-alive prior must hold it up so that
  // the covariance (R^T R)^-1 stays finite and bounded.
  const int p = 6;
  TypeParam rls(p, 0.98, 1e-6);
  Eigen::VectorXd x = Eigen::VectorXd::Constant(p, 2.0);
  x[0] = 1.0;
  for (int k = 0; k < 10'000; ++k) rls.update(x.data(), 1.0 + 1e-3 * std::sin(k));
  const auto r = rls.factor();
  const Eigen::MatrixXd rp = r.topLeftCorner(p, p);
  const Eigen::MatrixXd info = rp.transpose() * rp;
  ASSERT_TRUE(info.allFinite());
  const Eigen::VectorXd eig = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(info).eigenvalues();
  EXPECT_GT(eig.minCoeff(), 0.3e-6);  // covariance <= ~1/delta
  Eigen::VectorXd beta(p);
  rls.solve_prefix(p, beta);
  EXPECT_TRUE(beta.allFinite());
  EXPECT_TRUE(std::isfinite(rls.rss()));
}

}  // namespace
}  // namespace mpm
