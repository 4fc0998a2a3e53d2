// Square-root RLS: what only it does (the tracked inverse, the Wald tests,
// the one-pass update of large factors) against re-triangularisation and
// batch least squares. What every factor does: test_rls_factors.cpp.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "core/sqrt_rls.hpp"
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

// The Wald identity on the tracked inverse equals re-triangularisation for
// every block of a 6-input model, with and without forgetting, and tracking
// the inverse leaves the factor itself unchanged.
void expect_wald_matches(double lambda, int samples) {
  const std::size_t na = 3, nb = 4, m = 6, p = 1 + na + m * nb;
  SqrtRls plain(p, lambda, kDelta);
  SqrtRls tracked(p, lambda, kDelta, true);
  DataGen gen(static_cast<int>(p));
  Eigen::VectorXd x(static_cast<Eigen::Index>(p));
  double y = 0;
  for (int k = 0; k < samples; ++k) {
    gen.next(x, y);
    plain.update(x.data(), y);
    tracked.update(x.data(), y);
  }
  EXPECT_EQ((plain.factor() - tracked.factor()).norm(), 0.0);
  SqrtRls::Matrix scratch(static_cast<Eigen::Index>(p + 1), static_cast<Eigen::Index>(p + 1));
  for (std::size_t b = 0; b < m; ++b) {
    const std::size_t first = 1 + na + b * nb;
    const double ref = plain.rss_without(first, nb, scratch);
    const double wald = tracked.rss_without_wald(first, nb, scratch);
    EXPECT_NEAR(wald / ref, 1.0, 1e-9) << "block " << b << " lambda " << lambda;
    EXPECT_GT(ref, tracked.rss());  // the block explains something: a real check
  }
  // The AR block (inner, not an input) too.
  EXPECT_NEAR(tracked.rss_without_wald(1, na, scratch) / plain.rss_without(1, na, scratch), 1.0, 1e-9);
}

TEST(SqrtRls, WaldConditionalRssEqualsRetriangularisation) {
  expect_wald_matches(0.999, 5000);
  expect_wald_matches(1.0, 5000);
  expect_wald_matches(0.98, 3000);
}

TEST(SqrtRls, TrackedInverseStaysTheInverseOverLongRuns) {
  // Inverse QR-RLS carried for 3e5 samples: L R^T must still be I.
  for (double lambda : {1.0, 0.995}) {
    const int p = 9;
    SqrtRls rls(p, lambda, kDelta, true);
    DataGen gen(p);
    Eigen::VectorXd x(p);
    double y = 0;
    for (int k = 0; k < 300'000; ++k) {
      gen.next(x, y);
      rls.update(x.data(), y);
    }
    const Eigen::MatrixXd r = rls.factor().topLeftCorner(p, p);
    const Eigen::MatrixXd l = rls.inverse_factor();
    const Eigen::MatrixXd product = l * r.transpose();
    EXPECT_LT((product - Eigen::MatrixXd::Identity(p, p)).cwiseAbs().maxCoeff(), 1e-10) << lambda;
  }
}

// Block covariances tracked by rank-one downdates (plus one block
// recomputed a sample) equal re-triangularisation over long runs, through a
// stretch without excitation where the kept-alive prior takes over.
TEST(SqrtRls, TrackedBlockCovariancesStayExact) {
  const std::size_t nb = 4, m = 5, p = m * nb;
  for (double lambda : {1.0, 0.99}) {
    SqrtRls plain(p, lambda, 1e-6);
    SqrtRls blocks(p, lambda, 1e-6, true, nb);
    DataGen gen(static_cast<int>(p));
    Eigen::VectorXd x(static_cast<Eigen::Index>(p));
    double y = 0;
    SqrtRls::Matrix scratch(static_cast<Eigen::Index>(p + 1), static_cast<Eigen::Index>(p + 1));
    const auto check = [&](const char* when) {
      for (std::size_t b = 0; b + 1 < m; ++b) {  // the last block is trailing: a prefix sum either way
        const double ref = plain.rss_without(b * nb, nb, scratch);
        const double fast = blocks.rss_without_wald(b * nb, nb, scratch);
        EXPECT_NEAR(fast / ref, 1.0, 1e-8) << when << " block " << b << " lambda " << lambda;
      }
    };
    for (int k = 0; k < 100'000; ++k) {
      gen.next(x, y);
      if (k >= 40'000 && k < 42'000) x.tail(2 * nb).setConstant(1.5);  // two inputs frozen
      plain.update(x.data(), y);
      blocks.update(x.data(), y);
      if (k == 41'999) check("after the frozen stretch");
    }
    check("at the end");
    EXPECT_THROW(SqrtRls(p, lambda, 1e-6, false, nb), std::invalid_argument);  // needs the inverse
    EXPECT_THROW(SqrtRls(p + 1, lambda, 1e-6, true, nb), std::invalid_argument);  // whole blocks only
  }
}

TEST(SqrtRls, WaldFallsBackWithoutTrackedInverse) {
  const int p = 8;
  SqrtRls rls(p, 0.999, kDelta);
  DataGen gen(p);
  Eigen::VectorXd x(p);
  double y = 0;
  for (int k = 0; k < 500; ++k) {
    gen.next(x, y);
    rls.update(x.data(), y);
  }
  SqrtRls::Matrix scratch(p + 1, p + 1);
  EXPECT_EQ(rls.rss_without_wald(2, 3, scratch), rls.rss_without(2, 3, scratch));
  EXPECT_EQ(rls.rss_without_wald(5, 3, scratch), rls.rss_prefix(5));  // trailing block
}

// A large factor (the 20x20 and 50x50 monitors' full models) is updated in
// one pass over its rows: the sample, the kept-alive prior row when due, the
// coefficients and the RSS sums together. It must hold exactly what the
// lockstep update of the same rows holds (two factors updated together take
// that path), prior rows every sample (lambda 0.99), every few samples, and
// none; the tracked block covariances agree to rounding (the one-pass update
// re-synchronises a block after the prior row instead of before it).
TEST(SqrtRls, LargeFactorInOnePassEqualsLockstepUpdate) {
  const std::size_t nb = 10, m = 7, p = m * nb;  // above the one-pass threshold (64)
  for (double lambda : {0.99, 0.999, 1.0}) {
    SqrtRls alone(p, lambda, 1e-6, true, nb);
    SqrtRls pair_a(p, lambda, 1e-6, true, nb);
    SqrtRls pair_b(p, lambda, 1e-6, true, nb);
    SqrtRls* lockstep[] = {&pair_a, &pair_b};
    DataGen gen(static_cast<int>(p));
    Eigen::VectorXd x(static_cast<Eigen::Index>(p));
    double y = 0;
    for (int k = 0; k < 3000; ++k) {
      gen.next(x, y);
      if (k >= 1000 && k < 1400) x.segment(nb, 2 * nb).setConstant(0.5);  // two inputs frozen
      alone.update(x.data(), y);
      for (SqrtRls* s : lockstep) {
        std::copy(x.data(), x.data() + p, s->staged_row());
        s->staged_row()[p] = y;
      }
      SqrtRls::update_staged(lockstep, 2);
    }
    EXPECT_EQ((alone.factor() - pair_a.factor()).cwiseAbs().maxCoeff(), 0.0) << lambda;
    EXPECT_EQ((alone.inverse_factor() - pair_a.inverse_factor()).cwiseAbs().maxCoeff(), 0.0) << lambda;
    EXPECT_EQ((pair_a.factor() - pair_b.factor()).cwiseAbs().maxCoeff(), 0.0) << lambda;
    for (std::size_t k : {std::size_t{0}, nb, p / 2, p}) EXPECT_EQ(alone.rss_prefix(k), pair_a.rss_prefix(k)) << k;
    SqrtRls::Matrix scratch(static_cast<Eigen::Index>(p + 1), static_cast<Eigen::Index>(p + 1));
    for (std::size_t b = 0; b + 1 < m; ++b) {
      const double ref = alone.rss_without(b * nb, nb, scratch);
      EXPECT_NEAR(alone.rss_without_wald(b * nb, nb, scratch) / ref, 1.0, 1e-9) << "block " << b << " " << lambda;
      EXPECT_NEAR(pair_a.rss_without_wald(b * nb, nb, scratch) / ref, 1.0, 1e-9) << "block " << b << " " << lambda;
      EXPECT_GT(ref, alone.rss() * (1.0 + 1e-6)) << "block " << b;  // each block explains something
    }
  }
}

}  // namespace
}  // namespace mpm
