// The sequential detector on its ideal process: scores g = e x with e and
// x independent standard normals (known information I, variance 1), so
// T_W is exactly the chi-square process the thresholds are derived for.
// Checks the growing phase: normalised by the accumulated weight and with
// thresholds that follow the effective memory, the raises come at the
// stated rate and as often in the first half of each stream as in the
// second (the stationary thresholds alone crossed far more at the start).
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "core/chi_square.hpp"
#include "core/sequential_detector.hpp"

namespace mpm {
namespace {

TEST(SequentialDetector, ThresholdFollowsTheGrowingMemory) {
  DetectorSettings s;
  s.first_window = 200;
  s.windows = 3;
  s.sample_time = 1.0;
  s.false_alarms_per_year = 365.25 * 86400.0 / 1e5;
  SequentialDetector det(1, 4, s, 1, 16.0, 1.0);
  const double x[4] = {0.0, 0.0, 0.0, 0.0};
  // Before any sample the memory is nothing: the highest level; then the
  // level falls as the window fills, and equals the stationary one when full.
  double previous = INFINITY;
  for (int k = 0; k < 40000; ++k) {
    det.accumulate(0, x, 0.0, 1.0);
    for (std::size_t w = 0; w < det.windows(); ++w) {
      const double h = det.threshold_now(0, w);
      EXPECT_GE(h, det.threshold(w) - 1e-12);
      if (w == det.windows() - 1) {
        EXPECT_LE(h, previous + 1e-12) << "sample " << k;
        previous = h;
      }
    }
  }
  // Full (2 V within a part in 10^4 of W): the stationary level, to the
  // table's interpolation.
  for (std::size_t w = 0; w < det.windows(); ++w) EXPECT_NEAR(det.threshold_now(0, w), det.threshold(w), 1e-3);
  EXPECT_GT(det.threshold_now(0, 0), 0.0);
}

TEST(SequentialDetector, IdealProcessRaisesAtTheStatedRateFlatInTime) {
  constexpr std::size_t d = 4;
  constexpr double per_alarm = 4000.0;  // stated samples per false alarm
  DetectorSettings s;
  s.first_window = 100;
  s.window_ratio = 4.0;
  s.windows = 2;
  s.sample_time = 1.0;
  s.false_alarms_per_year = 365.25 * 86400.0 / per_alarm;
  s.crossing_constant = 1.2;  // the ideal process's (see the overview)
  const std::uint64_t period = 8;  // the long window looked at this often
  SequentialDetector det(1, d, s, 1, static_cast<double>(period), 1.0);
  const Eigen::MatrixXd identity = Eigen::MatrixXd::Identity(d, d);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal;
  const int streams = 300;
  const int length = 1600;  // the long window (400) fills in the first half
  std::size_t raises = 0, first_half = 0;
  double x[d];
  for (int r = 0; r < streams; ++r) {
    det.reset();
    for (int k = 0; k < length; ++k) {
      for (double& v : x) v = normal(rng);
      const double e = normal(rng);
      det.accumulate(0, x, e, e * e);
      DetectorEvent ev = DetectorEvent::kNone;
      {  // first window: T = |s|^2 / (sigma^2 V)
        const Eigen::Map<const Eigen::VectorXd> s0(det.sum(0, 0), d);
        ev = det.test(0, 0, s0.squaredNorm() / (det.variance(0, 0) * det.weight(0, 0)));
      }
      if ((k + 1) % static_cast<int>(period) == 0) {
        det.refresh_information(0, 1, identity, static_cast<double>(period));
        const DetectorEvent e1 = det.test(0, 1, det.normalised_quadratic(0, 1) / det.variance(0, 1));
        if (e1 == DetectorEvent::kRaised) ev = e1;
      }
      if (ev == DetectorEvent::kRaised) {
        ++raises;
        first_half += k < length / 2 ? 1 : 0;
      }
    }
  }
  const double stated = streams * length / per_alarm;
  const auto n = static_cast<double>(raises);
  const double lo = raises == 0 ? 0.0 : 0.5 * chi_square_quantile_upper(0.975, 2.0 * n);
  const double hi = 0.5 * chi_square_quantile_upper(0.025, 2.0 * n + 2.0);
  std::printf("%zu raises against %.1f stated (95%% CI %.2f..%.2f x); first half %zu\n", raises, stated, lo / stated,
              hi / stated, first_half);
  EXPECT_LE(lo / stated, 2.0);
  EXPECT_GE(hi / stated, 0.5);
  if (raises >= 8) {
    const double z = (static_cast<double>(first_half) - 0.5 * n) / std::sqrt(0.25 * n);
    EXPECT_LT(std::abs(z), 3.0) << first_half << " of " << raises << " raises in the first half";
  }
}

}  // namespace
}  // namespace mpm
