// The diagnosis library on a lag that the model lacks, on one input with two
// channels: an actuator lag (in front of the input's every channel) against
// an extra lag on one channel. Where the input's second channel is weak, the
// two forms fit alike; the column's other channel then does not contradict a
// common lag and the actuator is named, the channel's own lag its
// alternative. Where the second channel is strong and has no lag, the
// actuator's form loses its fit there, and the extra lag on the one channel
// is named.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "core/diagnosis.hpp"

namespace {

using mpm::DiscreteTf;
namespace dg = mpm::diagnosis;

constexpr double kPole = 0.9;
constexpr double kLagPole = 0.35;  // the lag the model lacks
constexpr double kNoiseSd = 0.05;

enum class Lag { actuator, channel_y1 };

// One input u (levels held 10 to 30 samples, N(0, 1)), outputs y1 and y2
// through g_j q^-1 / (1 - 0.9 q^-1), g1 = 0.1 and g2 = `y2_gain`; the plant
// lags u (actuator) or u's effect on y1 only (channel) by kLagPole; white
// noise of sd kNoiseSd on each output.
// Without `y2_modelled` the model has no channel u -> y2 (and y2_gain
// should be 0).
dg::Problem problem(Lag lag, double y2_gain, unsigned seed, bool y2_modelled = true) {
  const Eigen::Index n = 4000;
  std::mt19937 rng(seed);
  std::normal_distribution<double> level(0.0, 1.0), noise(0.0, kNoiseSd);
  std::uniform_int_distribution<int> hold(10, 30);
  const double gain[2] = {0.1, y2_gain};
  Eigen::VectorXd du(n);
  double held = 0.0, lagged = 0.0;
  double plant[2] = {0.0, 0.0}, model[2] = {0.0, 0.0};
  int next = 0;
  dg::Problem p;
  p.residual = Eigen::MatrixXd(n, 2);
  for (Eigen::Index k = 0; k < n; ++k) {
    for (int j = 0; j < 2; ++j) p.residual(k, j) = plant[j] - model[j] + noise(rng);
    if (k == next) {
      held = level(rng);
      next = static_cast<int>(k) + hold(rng);
    }
    du(k) = held;
    lagged = kLagPole * lagged + (1.0 - kLagPole) * held;
    for (int j = 0; j < 2; ++j) {
      const bool lags = lag == Lag::actuator || j == 0;
      plant[j] = kPole * plant[j] + gain[j] * (lags ? lagged : held);
      model[j] = kPole * model[j] + gain[j] * held;
    }
  }
  p.inputs = {"u"};
  p.outputs = {"y1", "y2"};
  p.du = Eigen::MatrixXd(n, 1);
  p.du.col(0) = du;
  p.u_abs = p.du;
  for (int j = 0; j < 2; ++j) p.nominal.push_back(DiscreteTf{{gain[j]}, {1.0, -kPole}, 1});
  if (!y2_modelled) p.nominal[1].reset();
  p.noise = {DiscreteTf{{1.0}, {1.0}, 0}, DiscreteTf{{1.0}, {1.0}, 0}};
  p.noise_variance = {kNoiseSd * kNoiseSd, kNoiseSd * kNoiseSd};
  p.monitor_flag = {true, false};
  p.monitor_located = {{0}, {}};
  return p;
}

std::string describe(const dg::Result& r) {
  std::string s;
  for (const auto& f : r.findings) {
    s += f.physics + " (" + f.summary + "; alternatives";
    for (const auto& a : f.alternatives) s += " " + a;
    s += "); ";
  }
  return s.empty() ? "no findings" : s;
}

TEST(DiagnosisActuator, AnActuatorLagWhoseSecondChannelIsWeakIsNamedTheActuator) {
  for (unsigned seed = 1; seed <= 12; ++seed) {
    const dg::Result r = dg::diagnose(problem(Lag::actuator, 0.005, seed));
    ASSERT_FALSE(r.findings.empty()) << "seed " << seed;
    const dg::Finding& f = r.findings.front();
    EXPECT_EQ(f.physics, "actuator_dynamics") << "seed " << seed << ": " << describe(r);
    EXPECT_EQ(f.channels.size(), 2u) << "seed " << seed << ": " << describe(r);
    EXPECT_LT(f.fit.holdout_variance_after, f.fit.holdout_variance_before) << "seed " << seed;
  }
}

TEST(DiagnosisActuator, AnExtraLagOnOneChannelBesideAStrongUnlaggedOneStaysTheChannels) {
  for (unsigned seed = 1; seed <= 12; ++seed) {
    const dg::Result r = dg::diagnose(problem(Lag::channel_y1, 0.1, seed));
    ASSERT_FALSE(r.findings.empty()) << "seed " << seed;
    const dg::Finding& f = r.findings.front();
    EXPECT_EQ(f.physics, "unmodeled_dynamics") << "seed " << seed << ": " << describe(r);
    ASSERT_EQ(f.channels.size(), 1u) << "seed " << seed << ": " << describe(r);
    EXPECT_EQ(f.channels[0].output, 0u) << "seed " << seed << ": " << describe(r);
    for (const auto& a : f.alternatives) EXPECT_NE(a, "actuator_dynamics") << "seed " << seed << ": " << describe(r);
  }
}

// Where u drives y1 alone, its actuator's lag and an extra lag on u -> y1
// are the same correction of the model's prediction: either truth is named
// the channel's lag, with the actuator among its alternatives, since no
// record could tell which.
TEST(DiagnosisActuator, OnAnInputWithOneChannelTheActuatorIsTheChannelLagsAlternative) {
  for (const Lag lag : {Lag::actuator, Lag::channel_y1}) {
    for (unsigned seed = 1; seed <= 6; ++seed) {
      const dg::Result r = dg::diagnose(problem(lag, 0.0, seed, false));
      const std::string what = std::string(lag == Lag::actuator ? "actuator" : "channel") + " lag, seed " +
                               std::to_string(seed) + ": " + describe(r);
      ASSERT_EQ(r.findings.size(), 1u) << what;
      const dg::Finding& f = r.findings.front();
      EXPECT_EQ(f.physics, "unmodeled_dynamics") << what;
      ASSERT_EQ(f.channels.size(), 1u) << what;
      EXPECT_EQ(f.channels[0].output, 0u) << what;
      EXPECT_NE(std::find(f.alternatives.begin(), f.alternatives.end(), "actuator_dynamics"), f.alternatives.end())
          << what;
    }
  }
}

}  // namespace
