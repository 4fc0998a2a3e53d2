// Square-root RLS against an independent batch least-squares reference
// (Householder QR over the stacked data), with and without forgetting.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "core/sqrt_rls.hpp"

namespace mpm {
namespace {

constexpr double kDelta = 1e-9;

// Batch reference: accumulates the R factor of [sqrt(w) X, sqrt(w) y] with
// Householder QR over blocks (TSQR), plus the prior rows sqrt(delta) I.
class BatchQr {
 public:
  explicit BatchQr(int p) : p_(p), r_(Eigen::MatrixXd::Zero(p + 1, p + 1)) {
    for (int i = 0; i < p; ++i) r_(i, i) = std::sqrt(kDelta);
  }
  void add_block(const Eigen::MatrixXd& rows) {  // rows: n x (p+1)
    Eigen::MatrixXd stacked(r_.rows() + rows.rows(), p_ + 1);
    stacked << r_, rows;
    Eigen::HouseholderQR<Eigen::MatrixXd> qr(stacked);
    r_ = qr.matrixQR().topRows(p_ + 1).triangularView<Eigen::Upper>();
  }
  // RSS of the LS fit on the regressor columns `keep` (indices < p).
  double rss(const std::vector<int>& keep) const {
    if (keep.empty()) return r_.col(p_).squaredNorm();
    Eigen::MatrixXd x(r_.rows(), static_cast<Eigen::Index>(keep.size()));
    for (std::size_t c = 0; c < keep.size(); ++c) x.col(static_cast<Eigen::Index>(c)) = r_.col(keep[c]);
    const Eigen::VectorXd y = r_.col(p_);
    const Eigen::VectorXd beta = x.colPivHouseholderQr().solve(y);
    return (y - x * beta).squaredNorm();
  }
  Eigen::VectorXd beta() const {
    return r_.topLeftCorner(p_, p_).triangularView<Eigen::Upper>().solve(r_.col(p_).head(p_));
  }

 private:
  int p_;
  Eigen::MatrixXd r_;
};

// ARX-like data: regressors correlated with each other and with y.
struct DataGen {
  std::mt19937_64 rng{42};
  std::normal_distribution<double> n{0.0, 1.0};
  Eigen::VectorXd state;
  explicit DataGen(int p) : state(Eigen::VectorXd::Zero(p)) {}
  void next(Eigen::Ref<Eigen::VectorXd> x, double& y) {
    for (Eigen::Index i = 0; i < state.size(); ++i) state[i] = 0.7 * state[i] + n(rng) + (i > 0 ? 0.3 * state[i - 1] : 0.0);
    x = state;
    x[0] = 1.0;  // intercept
    y = 0.5 + 0.8 * x[1] - 0.3 * x[x.size() - 1] + n(rng);
  }
};

std::vector<int> range_except(int p, int first, int count) {
  std::vector<int> v;
  for (int i = 0; i < p; ++i)
    if (i < first || i >= first + count) v.push_back(i);
  return v;
}

TEST(SqrtRls, EqualsBatchAfterAMillionSamples) {
  const int p = 7;
  SqrtRls rls(p, 1.0, kDelta);
  BatchQr batch(p);
  DataGen gen(p);
  const int n = 1'000'000, block = 20'000;
  Eigen::MatrixXd rows(block, p + 1);
  Eigen::VectorXd x(p);
  double y = 0;
  for (int k = 0; k < n; ++k) {
    gen.next(x, y);
    rls.update(x.data(), y);
    rows.row(k % block).head(p) = x.transpose();
    rows(k % block, p) = y;
    if ((k + 1) % block == 0) batch.add_block(rows);
  }
  const auto rel = [](double a, double b) { return std::abs(a - b) / std::abs(b); };
  EXPECT_LT(rel(rls.rss(), batch.rss(range_except(p, p, 0))), 1e-8);
  for (int k = 1; k <= p; ++k) EXPECT_LT(rel(rls.rss_prefix(static_cast<std::size_t>(k)), batch.rss(range_except(k, k, 0))), 1e-8) << k;
  SqrtRls::Matrix scratch(p + 1, p + 1);
  EXPECT_LT(rel(rls.rss_without(2, 3, scratch), batch.rss(range_except(p, 2, 3))), 1e-8);
  Eigen::VectorXd beta(p);
  rls.solve_prefix(p, beta);
  const Eigen::VectorXd ref = batch.beta();
  EXPECT_LT((beta - ref).norm() / ref.norm(), 1e-8);
}

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

TEST(SqrtRls, ForgettingEqualsWeightedBatch) {
  const int p = 5;
  const double lambda = 0.99;
  SqrtRls rls(p, lambda, kDelta);
  DataGen gen(p);
  const int n = 2000;
  Eigen::MatrixXd rows(n, p + 1);
  Eigen::VectorXd x(p);
  double y = 0;
  for (int k = 0; k < n; ++k) {
    gen.next(x, y);
    rls.update(x.data(), y);
    rows.row(k).head(p) = x.transpose();
    rows(k, p) = y;
  }
  for (int k = 0; k < n; ++k) rows.row(k) *= std::sqrt(std::pow(lambda, n - 1 - k));
  BatchQr batch(p);  // its prior is ~delta (the kept-alive prior is of the same size)
  batch.add_block(rows);
  EXPECT_NEAR(rls.rss() / batch.rss(range_except(p, p, 0)), 1.0, 1e-9);
  EXPECT_NEAR(rls.rss_prefix(2) / batch.rss(range_except(2, 2, 0)), 1.0, 1e-9);
}

TEST(SqrtRls, StaysBoundedWithoutExcitation) {
  // Inputs constant for 10^4 samples with forgetting: the information in the
  // unexcited directions decays; the kept-alive prior must hold it up so that
  // the covariance (R^T R)^-1 stays finite and bounded.
  const int p = 6;
  SqrtRls rls(p, 0.98, 1e-6);
  Eigen::VectorXd x = Eigen::VectorXd::Constant(p, 2.0);
  x[0] = 1.0;
  for (int k = 0; k < 10'000; ++k) rls.update(x.data(), 1.0 + 1e-3 * std::sin(k));
  const auto& r = rls.factor();
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
