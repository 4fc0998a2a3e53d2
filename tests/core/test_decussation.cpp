// Planted-truth tests of the decussation baseline (CAID + MQI). The plant is
// simulated here with plain loops (no simulator dependency): Wood-Berry-like
// first-order-plus-dead-time channels, y = G_P u + N a, and the residual
// d~ = y - G_M u that the method reads.
#include "core/decussation.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <utility>
#include <vector>

namespace {

using Eigen::MatrixXd;
using mpm::DecussationResult;
using mpm::DecussationSettings;
using mpm::DiscreteTf;

// gain q^-delay / (1 - pole q^-1)
struct Channel {
  double gain = 0.0;
  double pole = 0.0;
  std::size_t delay = 1;
};

using Plant = std::vector<std::vector<Channel>>;  // [output][input]

// Discretised Wood-Berry column (paper-notes.md, Case 1).
Plant wood_berry() {
  return {{{0.744, 0.9419, 2}, {-0.8789, 0.9535, 4}},
          {{0.5786, 0.9123, 8}, {-1.302, 0.9329, 4}}};
}

std::vector<double> filter_channel(const Channel& c, const std::vector<double>& u) {
  std::vector<double> y(u.size(), 0.0);
  for (std::size_t k = 0; k < u.size(); ++k) {
    const double previous = k > 0 ? y[k - 1] : 0.0;
    const double input = k >= c.delay ? u[k - c.delay] : 0.0;
    y[k] = c.pole * previous + c.gain * input;
  }
  return y;
}

// White noise through 1 / (1 - pole q^-1), scaled by `scale`.
std::vector<double> ar1(std::mt19937& rng, std::size_t n, double pole, double scale) {
  std::normal_distribution<double> white(0.0, 1.0);
  std::vector<double> x(n, 0.0);
  double state = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    state = pole * state + white(rng);
    x[k] = scale * state;
  }
  return x;
}

DiscreteTf noise_model(double pole, double num0 = 1.0) {
  DiscreteTf n;
  n.num = {num0};
  n.den = {1.0, -pole};
  return n;
}

// m(r, c) for the std::size_t loop counters of these tests.
double& at(MatrixXd& m, std::size_t r, std::size_t c) {
  return m(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c));
}

struct Data {
  MatrixXd u;
  MatrixXd residual;
  std::vector<DiscreteTf> noise;
};

constexpr std::size_t kSamples = 4000;
constexpr double kNoisePoles[2] = {0.8, 0.9};

// Open loop: independent filtered random inputs, d~ = (G_P - G_M) u + N a.
Data open_loop(const Plant& plant, const Plant& model, unsigned seed, double noise_num0 = 1.0) {
  std::mt19937 rng(seed);
  Data d;
  d.u.resize(kSamples, 2);
  d.residual.resize(kSamples, 2);
  std::vector<std::vector<double>> u;
  for (std::size_t i = 0; i < 2; ++i) u.push_back(ar1(rng, kSamples, 0.8, 1.0));
  for (std::size_t j = 0; j < 2; ++j) {
    std::vector<double> r = ar1(rng, kSamples, kNoisePoles[j], noise_num0);
    for (std::size_t i = 0; i < 2; ++i) {
      const std::vector<double> yp = filter_channel(plant[j][i], u[i]);
      const std::vector<double> ym = filter_channel(model[j][i], u[i]);
      for (std::size_t k = 0; k < kSamples; ++k) r[k] += yp[k] - ym[k];
    }
    for (std::size_t k = 0; k < kSamples; ++k) at(d.residual, k, j) = r[k];
    d.noise.push_back(noise_model(kNoisePoles[j], noise_num0));
  }
  for (std::size_t i = 0; i < 2; ++i) {
    for (std::size_t k = 0; k < kSamples; ++k) at(d.u, k, i) = u[i][k];
  }
  return d;
}

// Closed loop: u(k) = -K y(k-1) + dither, a diagonal proportional controller
// on the plant's own sign (u1 drives y1 up, u2 drives y2 down), so the inputs
// are correlated through the feedback.
Data closed_loop(const Plant& plant, const Plant& model, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> white(0.0, 1.0);
  const double k_gain[2] = {0.05, -0.05};
  std::vector<double> y_plant_state(4, 0.0), y_model_state(4, 0.0);
  std::vector<std::vector<double>> u_hist(2, std::vector<double>(kSamples, 0.0));
  double noise_state[2] = {0.0, 0.0};
  double y_prev[2] = {0.0, 0.0};
  Data d;
  d.u.resize(kSamples, 2);
  d.residual.resize(kSamples, 2);
  for (std::size_t k = 0; k < kSamples; ++k) {
    for (std::size_t i = 0; i < 2; ++i) u_hist[i][k] = -k_gain[i] * y_prev[i] + white(rng);
    for (std::size_t j = 0; j < 2; ++j) {
      noise_state[j] = kNoisePoles[j] * noise_state[j] + white(rng);
      double y = noise_state[j], ym = 0.0;
      for (std::size_t i = 0; i < 2; ++i) {
        const auto step = [&](const Channel& c, double& state) {
          const double in = k >= c.delay ? u_hist[i][k - c.delay] : 0.0;
          state = c.pole * state + c.gain * in;
          return state;
        };
        y += step(plant[j][i], y_plant_state[2 * j + i]);
        ym += step(model[j][i], y_model_state[2 * j + i]);
      }
      y_prev[j] = y;
      at(d.residual, k, j) = y - ym;
    }
    for (std::size_t i = 0; i < 2; ++i) at(d.u, k, i) = u_hist[i][k];
  }
  d.noise = {noise_model(kNoisePoles[0]), noise_model(kNoisePoles[1])};
  return d;
}

Plant with_g21_gain(double factor) {
  Plant p = wood_berry();
  p[1][0].gain *= factor;
  return p;
}

DecussationResult run(const Data& d, const DecussationSettings& s = {}) {
  return mpm::decussation(d.u, d.residual, d.noise, s);
}

TEST(Decussation, NoMismatchGivesMqiNearOneAndLocatesNothing) {
  for (unsigned seed : {1u, 2u, 3u}) {
    const DecussationResult r = run(open_loop(wood_berry(), wood_berry(), seed));
    ASSERT_EQ(r.mqi.size(), 2);
    for (int j = 0; j < 2; ++j) {
      EXPECT_NEAR(r.mqi(j), 1.0, 0.02) << "seed " << seed << " output " << j;
      EXPECT_NEAR(r.innovation_variance(j), 1.0, 0.1) << "seed " << seed << " output " << j;
    }
    EXPECT_FALSE(r.mismatch) << "seed " << seed;
    EXPECT_TRUE(r.located.empty()) << "seed " << seed;
  }
}

TEST(Decussation, NonMonicNoiseModelIsScaledNotMistakenForMismatch) {
  // N = 2 / (1 - p q^-1): the innovation is 2a; d_bar must not count the 2 twice.
  const DecussationResult r = run(open_loop(wood_berry(), wood_berry(), 7, 2.0));
  for (int j = 0; j < 2; ++j) EXPECT_NEAR(r.mqi(j), 1.0, 0.05) << "output " << j;
  EXPECT_FALSE(r.mismatch);
}

TEST(Decussation, GainMismatchOnG21FlagsOutput2AndLocatesTheChannel) {
  for (unsigned seed : {11u, 12u, 13u}) {
    const DecussationResult r = run(open_loop(with_g21_gain(1.5), wood_berry(), seed));
    EXPECT_NEAR(r.mqi(0), 1.0, 0.02) << "seed " << seed;
    EXPECT_LT(r.mqi(1), 0.9) << "seed " << seed;
    EXPECT_TRUE(r.mismatch);
    EXPECT_FALSE(r.output_flagged[0]);
    EXPECT_TRUE(r.output_flagged[1]);
    ASSERT_EQ(r.located.size(), 1u) << "seed " << seed;
    EXPECT_EQ(r.located[0], (std::pair<std::size_t, std::size_t>{1, 0}));
    // Delta G21 has 8 samples of dead time: the input leads the residual.
    EXPECT_GE(r.caid_lag(1, 0), 8);
    EXPECT_GT(r.caid(1, 0), 0.0);  // gain raised: Delta G21 has G21's sign (+)
  }
}

TEST(Decussation, LargerMismatchLowersMqiFurther) {
  const DecussationResult small = run(open_loop(with_g21_gain(1.2), wood_berry(), 21));
  const DecussationResult large = run(open_loop(with_g21_gain(2.0), wood_berry(), 21));
  EXPECT_LT(small.mqi(1), 0.99);
  EXPECT_LT(large.mqi(1), small.mqi(1));
  EXPECT_LT(large.mqi(1), 0.9);
}

TEST(Decussation, ClosedLoopMismatchStillFlagsTheRightOutput) {
  const DecussationResult clean = run(closed_loop(wood_berry(), wood_berry(), 31));
  EXPECT_NEAR(clean.mqi(0), 1.0, 0.05);
  EXPECT_NEAR(clean.mqi(1), 1.0, 0.05);
  EXPECT_FALSE(clean.mismatch);

  const DecussationResult bad = run(closed_loop(with_g21_gain(2.0), wood_berry(), 31));
  EXPECT_NEAR(bad.mqi(0), 1.0, 0.05);
  EXPECT_LT(bad.mqi(1), 0.85);
  EXPECT_TRUE(bad.output_flagged[1]);
  EXPECT_FALSE(bad.output_flagged[0]);
  // A weak controller with strong dither keeps the inputs nearly independent,
  // so CAID still names the column here (under a tight MPC it need not).
  EXPECT_EQ(bad.located, (std::vector<std::pair<std::size_t, std::size_t>>{{1, 0}}));
}

TEST(Decussation, NanRowsAreDroppedAndCutTheSeries) {
  const Data clean = open_loop(with_g21_gain(1.5), wood_berry(), 41);
  Data gappy = clean;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (Eigen::Index k : {500, 1700, 2900}) gappy.u(k, 1) = nan;
  for (Eigen::Index k = 2000; k < 2050; ++k) gappy.residual(k, 0) = nan;
  const DecussationResult a = run(clean);
  const DecussationResult b = run(gappy);
  EXPECT_LT(b.samples_used, a.samples_used);
  EXPECT_LT(b.regression_rows, a.regression_rows);
  for (int j = 0; j < 2; ++j) EXPECT_NEAR(b.mqi(j), a.mqi(j), 0.05) << "output " << j;
  EXPECT_EQ(b.located, a.located);
  EXPECT_TRUE(b.mqi.allFinite());
  EXPECT_TRUE(b.caid.allFinite());
}

TEST(Decussation, RejectsMismatchedSizes) {
  const Data d = open_loop(wood_berry(), wood_berry(), 51);
  const MatrixXd short_u = d.u.topRows(kSamples - 1);
  EXPECT_THROW(mpm::decussation(short_u, d.residual, d.noise), std::invalid_argument);
  const std::vector<DiscreteTf> one_noise = {d.noise[0]};
  EXPECT_THROW(mpm::decussation(d.u, d.residual, one_noise), std::invalid_argument);
  const MatrixXd no_inputs(kSamples, 0);
  EXPECT_THROW(mpm::decussation(no_inputs, d.residual, d.noise), std::invalid_argument);
}

TEST(Decussation, RejectsBadSettingsAndNoiseModels) {
  const Data d = open_loop(wood_berry(), wood_berry(), 52);
  DecussationSettings s;
  s.past_order = 0;
  EXPECT_THROW(run(d, s), std::invalid_argument);
  s = {};
  s.mqi_threshold = 1.5;
  EXPECT_THROW(run(d, s), std::invalid_argument);
  s = {};
  s.caid_threshold = 0.0;
  EXPECT_THROW(run(d, s), std::invalid_argument);

  Data not_invertible = d;
  not_invertible.noise[0].num = {0.0, 1.0};  // N(0) = 0: a enters one sample late
  EXPECT_THROW(run(not_invertible), std::invalid_argument);
  Data unstable = d;
  unstable.noise[1].den = {1.0, -1.1};
  EXPECT_THROW(run(unstable), std::invalid_argument);
}

TEST(Decussation, RejectsTooFewFiniteSamples) {
  Data d = open_loop(wood_berry(), wood_berry(), 53);
  // A NaN every 20 rows leaves runs too short for p = 10 plus N's settling.
  for (Eigen::Index k = 0; k < d.u.rows(); k += 20) d.u(k, 0) = std::nan("");
  EXPECT_THROW(run(d), std::invalid_argument);
  const Data tiny{d.u.topRows(30), d.residual.topRows(30), d.noise};
  EXPECT_THROW(run(tiny), std::invalid_argument);
}

}  // namespace
