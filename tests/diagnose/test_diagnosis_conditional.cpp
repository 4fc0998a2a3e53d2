// The diagnosis library on a small synthetic closed loop: a process-channel
// finding must improve the fit conditional on the recorded signals already
// accepted for the same output (fitted jointly with their regressors), not
// take up what a fixed subtraction of those signals left behind.
#include <cmath>
#include <cstddef>
#include <optional>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "core/diagnosis.hpp"
#include "support/diagnosis_problem.hpp"

namespace {

using mpm::DiscreteTf;
namespace dg = mpm::diagnosis;

// y = k G (u + z_in) + z_out + e with G = 0.1 q^-1 / (1 - 0.9 q^-1) the
// nominal model (k = 1: the plant has no process mismatch), under a PI
// controller that regulates y to 0 and so moves u to cancel z_in and z_out.
// z_in and z_out are recorded; their pulses overlap, so they are correlated
// with each other and, through the loop, with G u.
dg::Problem regulation_loop(unsigned seed, double plant_gain = 1.0) {
  const std::size_t n = 6000;
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.05), dither(0.0, 0.3);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n));
  Eigen::VectorXd y = u, gu = u, z_in = u, z_out = u;
  for (std::size_t k = 0; k < n; ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    const std::size_t block = k / 150;
    // Input pulses in blocks 1, 3 (mod 4); output pulses in blocks 1, 2: half
    // of each one's active time is shared with the other.
    if (block % 4 == 1 || block % 4 == 3) z_in(i) = (block % 8 < 4 ? 2.0 : -2.0);
    if (block % 4 == 1 || block % 4 == 2) z_out(i) = (block % 12 < 6 ? 1.0 : -1.0);
  }
  double x = 0.0, xm = 0.0, integ = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    y(i) = x + z_out(i) + noise(rng);
    gu(i) = xm;
    // The controller acts on y(k) for u(k), which reaches y from k + 1 on.
    integ += y(i);
    u(i) = -0.8 * y(i) - 0.05 * integ + dither(rng);
    x = 0.9 * x + 0.1 * plant_gain * (u(i) + z_in(i));
    xm = 0.9 * xm + 0.1 * u(i);
  }
  dg::Problem p = mpm::test::one_output_problem({"u"}, u, y - gu, {DiscreteTf{{0.1}, {1.0, -0.9}, 1}},
                                                 DiscreteTf{{1.0}, {1.0}, 0}, 0.05 * 0.05);
  p.extra_names = {"z_in", "z_out"};
  p.extra.resize(static_cast<Eigen::Index>(n), 2);
  p.extra.col(0) = z_in;
  p.extra.col(1) = z_out;
  return p;
}

TEST(DiagnosisConditional, RecordedSignalsLeaveNoSpuriousProcessFinding) {
  for (unsigned seed : {1u, 2u, 3u}) {
    const dg::Result r = dg::diagnose(regulation_loop(seed));
    EXPECT_TRUE(r.mismatch);
    std::size_t signals = 0;
    for (const auto& f : r.findings) {
      std::string what = f.physics + (f.signal ? " " + *f.signal : "") + ": " + f.summary;
      EXPECT_EQ(f.physics, "unmodeled_input") << "seed " << seed << ": " << what;
      for (const auto& c : f.channels) EXPECT_FALSE(c.input.has_value()) << "seed " << seed << ": " << what;
      signals += f.physics == "unmodeled_input";
    }
    EXPECT_EQ(signals, 2u) << "seed " << seed << ": both recorded signals drive y";
  }
}

// The symmetric case: a real gain mismatch of the same channel still earns
// its place next to the accepted signals.
TEST(DiagnosisConditional, RealGainMismatchIsKeptNextToRecordedSignals) {
  for (unsigned seed : {1u, 2u}) {
    const dg::Result r = dg::diagnose(regulation_loop(seed, 1.3));
    std::size_t signals = 0, gains = 0;
    for (const auto& f : r.findings) {
      signals += f.physics == "unmodeled_input";
      if (f.physics == "gain") {
        ++gains;
        ASSERT_EQ(f.channels.size(), 1u);
        EXPECT_EQ(f.channels[0].input, std::optional<std::size_t>(0));
        // Clearly above 1; not exactly 1.3, since z_in's structure (a first
        // order lag) was chosen while the gain error was still in the residual.
        EXPECT_GT(f.parameters.at("gain_factor"), 1.1) << f.summary;
        EXPECT_LT(f.parameters.at("gain_factor"), 1.4) << f.summary;
      }
    }
    EXPECT_EQ(signals, 2u) << "seed " << seed;
    EXPECT_EQ(gains, 1u) << "seed " << seed;
  }
}

}  // namespace
