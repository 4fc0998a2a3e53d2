// The diagnosis library on a 2x2 plant under decentralised PI control, where
// feedback makes the inputs move together and with the disturbances:
// * a gain that moves with each output's level (a process run away from the
//   point its model was linearised at) is named on every channel at once;
// * a changed disturbance model is named as such, and no process change
//   rides on it: G_M u mirrors the disturbance the controller rejects, so a
//   correction built from it can take up a noise model the whitener has
//   wrong, and every process hypothesis must explain the residual beyond an
//   AR(3) change of that model.
#include <cstddef>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "core/diagnosis.hpp"

namespace {

using mpm::DiscreteTf;
namespace dg = mpm::diagnosis;

constexpr double kPole = 0.8;                       // every channel g q^-1 / (1 - 0.8 q^-1)
constexpr double kGain[2][2] = {{0.2, 0.06}, {0.05, 0.2}};  // [output][input]
constexpr double kNoiseSd = 0.05;

struct Plant {
  double level_slope = 0.0;     // y = x (1 + b x), x = G u
  double y1_noise_pole = kPole;  // the disturbance model N = 1 / (1 - pole q^-1) of y1 (declared: kPole)
};

dg::Problem closed_loop(const Plant& plant, unsigned seed) {
  const Eigen::Index n = 4000;
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, kNoiseSd);
  std::uniform_int_distribution<int> hold(150, 400);
  std::uniform_real_distribution<double> level(-1.5, 1.5);
  double state[2][2] = {{0.0, 0.0}, {0.0, 0.0}};  // channel states
  double v[2] = {0.0, 0.0}, r[2] = {0.0, 0.0}, integral[2] = {0.0, 0.0};
  int next[2] = {0, 0};
  Eigen::MatrixXd du(n, 2), residual(n, 2);
  for (Eigen::Index k = 0; k < n; ++k) {
    double y[2], x[2];
    for (int j = 0; j < 2; ++j) {
      x[j] = state[j][0] + state[j][1];  // strictly proper: u(k) acts from k + 1
      v[j] = (j == 0 ? plant.y1_noise_pole : kPole) * v[j] + noise(rng);
      y[j] = x[j] * (1.0 + plant.level_slope * x[j]) + v[j];
      residual(k, j) = y[j] - x[j];
      if (k == next[j]) {
        r[j] = level(rng);
        next[j] = static_cast<int>(k) + hold(rng);
      }
    }
    double u[2];
    for (int i = 0; i < 2; ++i) {  // PI: input i holds output i on its setpoint
      const double e = r[i] - y[i];
      integral[i] += e;
      u[i] = 1.0 * e + 0.15 * integral[i];
      du(k, i) = u[i];
    }
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) state[j][i] = kPole * state[j][i] + kGain[j][i] * u[i];
  }
  dg::Problem p;
  p.inputs = {"u1", "u2"};
  p.outputs = {"y1", "y2"};
  p.u_abs = du;
  p.du = du;
  p.residual = residual;
  for (int j = 0; j < 2; ++j)
    for (int i = 0; i < 2; ++i) p.nominal.push_back(DiscreteTf{{kGain[j][i]}, {1.0, -kPole}, 1});
  for (int j = 0; j < 2; ++j) {
    p.noise.push_back(DiscreteTf{{1.0}, {1.0, -kPole}, 0});
    p.noise_variance.push_back(kNoiseSd * kNoiseSd);  // of the white input, as the plant format says
  }
  p.monitor_flag = {false, false};
  p.monitor_located = {{}, {}};
  return p;
}

std::string describe(const dg::Result& r) {
  std::string s;
  for (const auto& f : r.findings) s += f.physics + " (" + f.summary + "); ";
  return s.empty() ? "no findings" : s;
}

bool names(const dg::Finding& f, std::size_t output, std::size_t input) {
  for (const auto& c : f.channels)
    if (c.output == output && c.input == input) return true;
  return false;
}

TEST(DiagnosisFeedback, GainThatMovesWithTheLevelsIsOneFindingOnEveryChannel) {
  for (unsigned seed : {1u, 2u, 3u}) {
    const dg::Result r = dg::diagnose(closed_loop(Plant{0.08, kPole}, seed));
    const std::string what = "seed " + std::to_string(seed) + ": " + describe(r);
    ASSERT_EQ(r.findings.size(), 1u) << what;
    const dg::Finding& f = r.findings.front();
    EXPECT_EQ(f.physics, "nonlinear_gain") << what;
    for (std::size_t j = 0; j < 2; ++j)
      for (std::size_t i = 0; i < 2; ++i) EXPECT_TRUE(names(f, j, i)) << what << " misses y" << j + 1 << " <- u" << i + 1;
    EXPECT_NEAR(f.parameters.at("gain_slope_per_unit_y1"), 0.08, 0.02) << what;
    EXPECT_LT(f.fit.holdout_variance_after, f.fit.holdout_variance_before) << what;
  }
}

TEST(DiagnosisFeedback, ChangedDisturbanceModelIsNoProcessChange) {
  for (unsigned seed = 1; seed <= 8; ++seed) {
    const dg::Result r = dg::diagnose(closed_loop(Plant{0.0, 0.93}, seed));
    const std::string what = "seed " + std::to_string(seed) + ": " + describe(r);
    for (const auto& f : r.findings)
      for (const auto& c : f.channels) EXPECT_FALSE(c.input.has_value()) << what;
    ASSERT_FALSE(r.findings.empty()) << what;
    EXPECT_EQ(r.findings.front().physics, "disturbance_model") << what;
  }
}

}  // namespace
