// Square-root RLS: the conditional RSS by re-triangularisation against
// batch least squares on every subset. What every factor does:
// test_rls_factors.cpp.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "support/sqrt_rls.hpp"
#include "support/batch_qr.hpp"

namespace mpm {
namespace {

using test::BatchQr;
using test::DataGen;
using test::kDelta;
using test::range_except;

TEST(SqrtRls, RssWithoutEveryBlockMatchesBatchOnSubsets) {
  const int p = 12;
  SqrtRls rls(p, 1.0, kDelta);
  BatchQr batch(p);
  DataGen gen(p);
  Eigen::MatrixXd rows(3000, p + 1);
  Eigen::VectorXd x(p);
  double y = 0;
  for (int k = 0; k < 3000; ++k) {
    gen.next(x, y);
    rls.update(x.data(), y);
    rows.row(k).head(p) = x.transpose();
    rows(k, p) = y;
  }
  batch.add_block(rows);
  SqrtRls::Matrix scratch(p + 1, p + 1);
  for (int first = 0; first < p; ++first)
    for (int count = 1; first + count <= p; ++count) {
      const double ref = batch.rss(range_except(p, first, count));
      EXPECT_NEAR(rls.rss_without(static_cast<std::size_t>(first), static_cast<std::size_t>(count), scratch) / ref, 1.0, 1e-10)
          << first << "+" << count;
    }
}

}  // namespace
}  // namespace mpm
