// The data of the paper's location plots (core/paper_plots.hpp). Planted
// truth: an ARX residual d(k) = 0.9 d(k-1) + 0.5 u1(k-1) + a(k) with u1, u2
// and a white; and an exact noise-free ARX whose coefficients the fit must
// recover.
#include "core/paper_plots.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

namespace mpm {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct Arx {
  Eigen::VectorXd d;
  Eigen::MatrixXd u;
};

Arx planted(Eigen::Index n, double noise, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  Arx s{Eigen::VectorXd::Zero(n), Eigen::MatrixXd::Zero(n, 2)};
  for (Eigen::Index k = 0; k < n; ++k) {
    s.u(k, 0) = g(rng);
    s.u(k, 1) = g(rng);
    const double prev = k ? s.d(k - 1) : 0.0, u1 = k ? s.u(k - 1, 0) : 0.0;
    s.d(k) = 0.9 * prev + 0.5 * u1 + noise * g(rng);
  }
  return s;
}

TEST(OrderSweep, VariancesAndArPartAreThePapersOnAPlantedArx) {
  const Arx s = planted(20000, 1.0, 3);
  const OrderSweep w = order_sweep(s.d, s.u, 20, 2);
  ASSERT_EQ(w.variance.size(), 2u);
  ASSERT_EQ(w.variance[0].size(), 3u);
  ASSERT_EQ(w.variance[0][0].size(), 20u);
  // u1 carries the mismatch: without its lags the AR fit leaves 0.5 u1(k-1)
  // + a, variance 1.25; with them, var(a) = 1.
  EXPECT_NEAR(w.variance[0][0][0], 1.25, 0.05);
  EXPECT_NEAR(w.variance[0][1][0], 1.0, 0.04);
  EXPECT_NEAR(w.variance[0][2][19], 1.0, 0.04);
  // u2 has no effect: its curves lie on the AR-only curve.
  for (std::size_t na = 1; na <= 20; ++na) EXPECT_NEAR(w.variance[1][2][na - 1] / w.variance[1][0][na - 1], 1.0, 2e-3);
  // Nested least squares: more regressors never leave more variance.
  for (std::size_t i = 0; i < 2; ++i)
    for (std::size_t nb = 0; nb <= 2; ++nb)
      for (std::size_t na = 1; na < 20; ++na) {
        EXPECT_LE(w.variance[i][nb][na], w.variance[i][nb][na - 1] + 1e-12);
        if (nb) {
          EXPECT_LE(w.variance[i][nb][na], w.variance[i][nb - 1][na] + 1e-12);
        }
      }
  // Beside u1's lags the AR part is that of 1 - N^-1 = 0.9 q^-1.
  EXPECT_NEAR(w.ar[0][0], 0.9, 0.02);
  for (std::size_t l = 1; l < 20; ++l) EXPECT_NEAR(w.ar[0][l], 0.0, 0.03) << l;
  EXPECT_EQ(w.used, 20000u - 20u);
}

TEST(OrderSweep, RecoversAnExactArxAndItsZeroVariance) {
  const Arx s = planted(400, 0.0, 4);
  // u1 white: excitation enough; noise free: the fit is exact.
  const OrderSweep w = order_sweep(s.d, s.u, 3, 1);
  EXPECT_NEAR(w.ar[0][0], 0.9, 1e-8);
  EXPECT_NEAR(w.ar[0][1], 0.0, 1e-8);
  EXPECT_NEAR(w.variance[0][1][0], 0.0, 1e-12);
  EXPECT_GT(w.variance[1][1][0], 0.1);  // u2's lags cannot explain u1's effect
}

TEST(OrderSweep, LeavesOutRowsWhoseLagsReachAMissingValue) {
  Arx s = planted(1000, 1.0, 5);
  const std::size_t full = order_sweep(s.d, s.u, 5, 2).used;
  EXPECT_EQ(full, 1000u - 5u);
  s.d(500) = kNaN;  // rows 500..505 lose the target or a lag
  EXPECT_EQ(order_sweep(s.d, s.u, 5, 2).used, full - 6u);
  s.u(700, 1) = kNaN;  // rows 701, 702 lose an input lag
  const OrderSweep w = order_sweep(s.d, s.u, 5, 2);
  EXPECT_EQ(w.used, full - 8u);
  for (const auto& per_input : w.variance)
    for (const auto& curve : per_input)
      for (double v : curve) EXPECT_TRUE(std::isfinite(v));
}

TEST(OrderSweep, TooFewRowsGiveNaNAndBadArgumentsThrow) {
  const Arx s = planted(10, 1.0, 6);
  const OrderSweep w = order_sweep(s.d, s.u, 20, 2);
  EXPECT_EQ(w.used, 0u);
  EXPECT_TRUE(std::isnan(w.variance[0][0][0]));
  EXPECT_TRUE(std::isnan(w.ar[1][0]));
  EXPECT_THROW(order_sweep(s.d, s.u, 0, 2), std::invalid_argument);
  EXPECT_THROW(order_sweep(s.d, s.u, 2, -1), std::invalid_argument);
  EXPECT_THROW(order_sweep(s.d, Eigen::MatrixXd::Zero(9, 2), 2, 1), std::invalid_argument);
}

TEST(DetectorEvidence, IsTheLargestStatisticOverItsThreshold) {
  DetectorSettings set;
  set.first_window = 200;
  set.windows = 3;
  set.sample_time = 1.0;
  SequentialDetector det(1, 4, set, 1, 16.0, 1.0);
  EXPECT_EQ(detector_evidence(det, 0), 0.0);  // nothing looked at yet
  const double x[4] = {0.0, 0.0, 0.0, 0.0};
  for (int k = 0; k < 1000; ++k) det.accumulate(0, x, 0.0, 1.0);
  det.test(0, 0, 3.0);
  det.test(0, 2, 0.5 * det.threshold_now(0, 2));
  const double first = 3.0 / det.threshold_now(0, 0);
  EXPECT_DOUBLE_EQ(detector_evidence(det, 0), std::max(first, 0.5));
  det.test(0, 1, 2.0 * det.threshold_now(0, 1));
  EXPECT_DOUBLE_EQ(detector_evidence(det, 0), 2.0);
}

}  // namespace
}  // namespace mpm
