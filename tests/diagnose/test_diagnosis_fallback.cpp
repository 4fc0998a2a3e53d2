// The monitor's fallback in the diagnosis: where no hypothesis explains the
// record, each output the monitor flags is reported as an `other` finding at
// the monitor's location; beside findings that explain the record, a flagged
// output that none touches is not made a finding of its own (the report's
// loops keep its flag).
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "core/diagnosis.hpp"

namespace {

using mpm::DiscreteTf;
namespace dg = mpm::diagnosis;

const DiscreteTf kChannel{{0.1}, {1.0, -0.9}, 1};

// Two inputs, two outputs, y_j <- u_j through kChannel; the plant's y1
// channel has gain `gain1` x the model's; white noise of sd 0.05. The
// monitor flags both outputs at the given location.
dg::Problem two_loops(unsigned seed, double gain1) {
  const Eigen::Index n = 3000;
  std::mt19937 rng(seed);
  std::normal_distribution<double> level(0.0, 0.7), noise(0.0, 0.05);
  Eigen::MatrixXd du(n, 2);
  double held[2] = {0.0, 0.0};
  for (Eigen::Index k = 0; k < n; ++k)
    for (int i = 0; i < 2; ++i) {
      if (k % (10 + 3 * i) == 0) held[i] = level(rng);
      du(k, i) = held[i];
    }
  dg::Problem p;
  p.inputs = {"u1", "u2"};
  p.outputs = {"y1", "y2"};
  p.du = du;
  p.u_abs = du;
  p.residual = Eigen::MatrixXd(n, 2);
  Eigen::VectorXd g1 = Eigen::VectorXd::Zero(n);
  for (Eigen::Index k = 2; k < n; ++k) g1(k) = 0.9 * g1(k - 1) + 0.1 * du(k - 1, 0);
  for (Eigen::Index k = 0; k < n; ++k) {
    p.residual(k, 0) = (gain1 - 1.0) * g1(k) + noise(rng);
    p.residual(k, 1) = noise(rng);
  }
  p.nominal = {kChannel, std::nullopt, std::nullopt, kChannel};
  p.noise = {DiscreteTf{{1.0}, {1.0}, 0}, DiscreteTf{{1.0}, {1.0}, 0}};
  p.noise_variance = {0.05 * 0.05, 0.05 * 0.05};
  p.monitor_flag = {true, true};
  p.monitor_located = {{0}, {1}};
  return p;
}

TEST(DiagnosisFallback, FlaggedOutputsAreOtherOnlyWhereNothingWasFound) {
  // Nothing to find: both flags become `other` findings at the monitor's location.
  const dg::Result none = dg::diagnose(two_loops(5, 1.0));
  ASSERT_EQ(none.findings.size(), 2u);
  for (std::size_t j = 0; j < 2; ++j) {
    EXPECT_EQ(none.findings[j].physics, "other");
    ASSERT_EQ(none.findings[j].channels.size(), 1u);
    EXPECT_EQ(none.findings[j].channels[0].output, j);
    EXPECT_EQ(none.findings[j].channels[0].input, std::optional<std::size_t>(j));
  }
  EXPECT_TRUE(none.mismatch);
  // y1's gain is found: y2's flag, which nothing explains, is no finding.
  const dg::Result found = dg::diagnose(two_loops(5, 1.4));
  ASSERT_EQ(found.findings.size(), 1u) << found.findings.back().summary;
  EXPECT_EQ(found.findings[0].physics, "gain");
  EXPECT_EQ(found.findings[0].channels[0].output, 0u);
  EXPECT_TRUE(found.mismatch);
}

}  // namespace
