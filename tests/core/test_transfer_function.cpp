// Transfer functions: ZOH discretisation checked against the paper's
// Wood-Berry numbers and against exact continuous step responses.
#include <cmath>

#include <gtest/gtest.h>

#include "core/noise_filter.hpp"
#include "core/transfer_function.hpp"
#include "support/tf_step.hpp"

namespace mpm {
namespace {

using test::tf_step;

TEST(Zoh, WoodBerryChannelsMatchPaper) {
  struct Case { ContinuousTf g; double b; double a; int delay; };
  const Case cases[] = {
      {{{12.8}, {16.7, 1}, 1.0}, 0.744, -0.9419, 2},
      {{{-18.9}, {21, 1}, 3.0}, -0.8789, -0.9535, 4},
      {{{6.6}, {10.9, 1}, 7.0}, 0.5786, -0.9123, 8},
      {{{-19.4}, {14.4, 1}, 3.0}, -1.302, -0.9329, 4},
  };
  for (const auto& c : cases) {
    const DiscreteTf d = discretize_zoh(c.g, 1.0);
    ASSERT_EQ(d.num.size(), 1u);
    ASSERT_EQ(d.den.size(), 2u);
    EXPECT_NEAR(d.num[0], c.b, 6e-4);
    EXPECT_NEAR(d.den[1], c.a, 6e-5);
    EXPECT_EQ(d.delay, c.delay);
  }
}

TEST(Zoh, FractionalDeadTimeMatchesExactStepResponse) {
  // K e^{-tau s}/(T s + 1): y(t) = K (1 - e^{-(t - tau)/T}) for t > tau.
  const double K = 2.0, T = 7.0, tau = 2.6, ts = 1.0;
  const DiscreteTf d = discretize_zoh({{K}, {T, 1}, tau}, ts);
  const auto y = tf_step(d, 40);
  for (int k = 0; k < 40; ++k) {
    const double t = k * ts;
    const double exact = t > tau ? K * (1 - std::exp(-(t - tau) / T)) : 0.0;
    EXPECT_NEAR(y[static_cast<std::size_t>(k)], exact, 1e-10) << "k=" << k;
  }
}

TEST(Zoh, IntegratingSecondOrderMatchesExactStepResponse) {
  // 1/(s (s + 1)): y(t) = t - 1 + e^{-t}, sampled at 0.5 s.
  const DiscreteTf d = discretize_zoh({{1}, {1, 1, 0}, 0.0}, 0.5);
  EXPECT_TRUE(d.has_integrator());
  EXPECT_FALSE(d.is_stable());
  const auto y = tf_step(d, 30);
  for (int k = 0; k < 30; ++k) {
    const double t = 0.5 * k;
    EXPECT_NEAR(y[static_cast<std::size_t>(k)], t - 1 + std::exp(-t), 1e-9) << "k=" << k;
  }
}

TEST(Zoh, ProperChannelWithFeedthroughAndZero) {
  // (s + 2)/(s + 1) = 1 + 1/(s + 1): y(t) = 2 - e^{-t} for a step.
  const DiscreteTf d = discretize_zoh({{1, 2}, {1, 1}, 0.0}, 0.2);
  const auto y = tf_step(d, 20);
  for (int k = 0; k < 20; ++k) EXPECT_NEAR(y[static_cast<std::size_t>(k)], 2 - std::exp(-0.2 * k), 1e-10);
}

TEST(Zoh, RejectsImproperAndInvalid) {
  EXPECT_THROW(discretize_zoh({{1, 0, 0}, {1, 1}, 0.0}, 1.0), std::invalid_argument);
  EXPECT_THROW(discretize_zoh({{1}, {1, 1}, -1.0}, 1.0), std::invalid_argument);
  EXPECT_THROW(discretize_zoh({{1}, {1, 1}, 0.0}, 0.0), std::invalid_argument);
  EXPECT_THROW(discretize_zoh({{1}, {0}, 0.0}, 1.0), std::invalid_argument);
}

TEST(DiscreteFilter, DelayAndDcGain) {
  DiscreteTf tf{{0.5}, {1, -0.5}, 3};
  EXPECT_DOUBLE_EQ(tf.dc_gain(), 1.0);
  const auto y = tf_step(tf, 60);
  EXPECT_EQ(y[0], 0.0);
  EXPECT_EQ(y[2], 0.0);
  EXPECT_DOUBLE_EQ(y[3], 0.5);
  EXPECT_NEAR(y[59], 1.0, 1e-12);
}

TEST(DiscreteFilter, ResetPutsStableFilterAtSteadyState) {
  DiscreteFilter f(DiscreteTf{{0.2}, {1, -0.8}, 2});
  f.reset(3.0);
  for (int k = 0; k < 5; ++k) EXPECT_NEAR(f.step(3.0), 3.0, 1e-12);
}

TEST(NoiseModel, InverseArCoefficients) {
  // N = 1/(1 - 0.9 q^-1): 1 - N^-1 = 0.9 q^-1, nothing else.
  const auto g = inverse_noise_ar_coefficients(DiscreteTf{{1}, {1, -0.9}, 0}, 5);
  ASSERT_EQ(g.size(), 5u);
  EXPECT_NEAR(g[0], 0.9, 1e-15);
  for (std::size_t j = 1; j < 5; ++j) EXPECT_EQ(g[j], 0.0);
  // N = (1 + 0.5 q^-1): N^-1 = 1 - 0.5 q^-1 + 0.25 q^-2 ..., so g_j = -(-0.5)^j.
  const auto h = inverse_noise_ar_coefficients(DiscreteTf{{1, 0.5}, {1}, 0}, 4);
  for (std::size_t j = 0; j < 4; ++j) EXPECT_NEAR(h[j], -std::pow(-0.5, static_cast<double>(j + 1)), 1e-15);
}

TEST(NoiseModel, RejectsNonInvertible) {
  EXPECT_THROW(inverse(DiscreteTf{{0, 1}, {1, -0.5}, 0}), std::invalid_argument);   // num[0] = 0
  EXPECT_THROW(inverse(DiscreteTf{{1, 2}, {1, -0.5}, 0}), std::invalid_argument);   // zero at z = -2
  EXPECT_THROW(inverse(DiscreteTf{{1}, {1, -0.5}, 1}), std::invalid_argument);      // delay
}

}  // namespace
}  // namespace mpm
