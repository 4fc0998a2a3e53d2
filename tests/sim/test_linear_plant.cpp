// The linear plant: without edits it is the model; each edit changes the
// response the way its physics says.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <utility>

#include "core/mimo_model.hpp"
#include "sim/linear_process.hpp"
#include "sim/sim_test_support.hpp"

namespace mpm::sim {
namespace {

using testing::build;
using testing::example_plant;
using testing::step_response;

constexpr std::size_t kN = 400;

std::vector<double> column(const std::vector<std::vector<double>>& y, std::size_t j) {
  std::vector<double> c;
  for (const auto& row : y) c.push_back(row[j]);
  return c;
}

// Feeds the same random inputs to the plant (y(k) read before u(k) is
// applied) and to MimoModel (y(k) = G u(k)): strictly proper channels make
// them the same sequence.
void expect_reproduces_model(const PlantModel& m) {
  Plant plant = build(m);
  MimoModel model(m);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n01;
  std::vector<double> u(m.n_inputs()), y(m.n_outputs()), ym(m.n_outputs()), zero(m.n_outputs(), 0.0);
  for (int k = 0; k < 2000; ++k) {
    for (double& x : u) x = n01(rng);
    plant.measure(zero.data(), y.data());
    model.step(u.data(), ym.data());
    for (std::size_t j = 0; j < y.size(); ++j) ASSERT_EQ(y[j], ym[j]) << m.name << " output " << j << " at k=" << k;
    plant.apply(u.data(), nullptr);
  }
}

TEST(LinearPlant, WithoutEditsReproducesTheModelExactly) {
  expect_reproduces_model(example_plant("wood-berry.yaml"));
  expect_reproduces_model(example_plant("wood-berry-continuous.yaml"));
  expect_reproduces_model(example_plant("quad-tank-4x4.yaml"));  // explicit zeros, 2nd order
}

TEST(LinearPlant, DirectFeedthroughIsRejected) {
  PlantModel m = example_plant("wood-berry.yaml");
  m.channels[0].tf.delay = 0;  // y1 would react to u1 within the sample
  EXPECT_THROW(build(m), std::invalid_argument);
}

struct Responses {
  std::vector<std::vector<double>> nominal, edited;
};

Responses responses(const PlantModel& m, const PlantSpec& spec, const std::vector<double>& u) {
  Plant a = build(m);
  Plant b = build(m, spec);
  return {step_response(a, u, kN), step_response(b, u, kN)};
}

// A plant spec of one channel, input or output edit (named with designated
// initialisers at the call: {.output = "y2", .input = "u1", .gain_factor = 1.2}).
PlantSpec one_edit(ChannelEdit e) {
  PlantSpec spec;
  spec.channels = {std::move(e)};
  return spec;
}

PlantSpec one_edit(InputEdit e) {
  PlantSpec spec;
  spec.inputs = {std::move(e)};
  return spec;
}

TEST(LinearPlant, GainEditScalesOnlyThatChannelsSteadyState) {
  const PlantModel m = example_plant("wood-berry.yaml");
  const auto r = responses(m, one_edit({.output = "y2", .input = "u1", .gain_factor = 1.2}), {1.0, 0.0});
  EXPECT_NEAR(r.edited.back()[1] / r.nominal.back()[1], 1.2, 1e-9);
  for (std::size_t k = 0; k < kN; ++k) {
    EXPECT_DOUBLE_EQ(r.edited[k][0], r.nominal[k][0]);  // y1 <- u1 untouched
    EXPECT_NEAR(r.edited[k][1], 1.2 * r.nominal[k][1], 1e-9);
  }
}

// v / (1 + a|v|) in front of y2 <- u1: a step of +-2 at a = 0.5 acts as
// +-1, odd; the other channels see the input as it is.
TEST(LinearPlant, SoftSaturationMapsTheChannelsInputOddly) {
  const PlantModel m = example_plant("wood-berry.yaml");
  for (const double step : {2.0, -2.0}) {
    const auto r = responses(m, one_edit({.output = "y2", .input = "u1", .soft_saturation = 0.5}), {step, 0.0});
    for (std::size_t k = 0; k < kN; ++k) {
      EXPECT_DOUBLE_EQ(r.edited[k][0], r.nominal[k][0]);  // y1 <- u1 untouched
      EXPECT_NEAR(r.edited[k][1], 0.5 * r.nominal[k][1], 1e-9) << "step " << step << " k " << k;
    }
    EXPECT_NE(r.nominal.back()[1], 0.0);
  }
}

TEST(LinearPlant, DelayEditShiftsTheStepResponse) {
  const PlantModel m = example_plant("wood-berry.yaml");
  const auto r = responses(m, one_edit({.output = "y1", .input = "u2", .extra_delay = 3}), {0.0, 1.0});
  for (std::size_t k = 0; k < kN; ++k) {
    const double shifted = k >= 3 ? r.nominal[k - 3][0] : 0.0;
    EXPECT_DOUBLE_EQ(r.edited[k][0], shifted) << k;
  }
  EXPECT_NE(r.nominal[4][0], 0.0);  // delay 4: the nominal moves at sample 4
  EXPECT_EQ(r.edited[6][0], 0.0);
}

// The paper's G12 edit: pole 0.9535 -> 0.9535 * 0.9, numerator unchanged.
TEST(LinearPlant, PoleEditMovesThePoleAndWithItTheGain) {
  const PlantModel m = example_plant("wood-berry.yaml");
  const DiscreteTf tf = edited_channel(m.channel(0, 1), {.output = "y1", .input = "u2", .pole_factor = 0.9}, 1.0);
  ASSERT_EQ(tf.den.size(), 2u);
  EXPECT_NEAR(tf.den[1], -0.9535 * 0.9, 1e-12);
  EXPECT_NEAR(tf.dc_gain(), -0.8789 / (1 - 0.9535 * 0.9), 1e-9);
  EXPECT_EQ(tf.delay, 4);
}

// Time to reach 63 % of the final value, in samples.
std::size_t rise_time(const std::vector<double>& y) {
  const double target = 0.632 * y.back();
  for (std::size_t k = 0; k < y.size(); ++k)
    if (std::abs(y[k]) >= std::abs(target)) return k;
  return y.size();
}

TEST(LinearPlant, TimeConstantEditKeepsTheGainAndSpeedsUp) {
  const PlantModel m = example_plant("wood-berry.yaml");
  const ChannelEdit faster{.output = "y2", .input = "u1", .time_constant_factor = 0.7};
  const auto r = responses(m, one_edit(faster), {1.0, 0.0});
  EXPECT_NEAR(r.edited.back()[1], r.nominal.back()[1], 1e-6);
  const double tau_nominal = -1.0 / std::log(0.9123);
  const DiscreteTf tf = edited_channel(m.channel(1, 0), faster, 1.0);
  EXPECT_NEAR(-1.0 / std::log(-tf.den[1]), 0.7 * tau_nominal, 1e-9);
  // Dead time 8 samples in both; the lag part is 30 % faster.
  EXPECT_LT(rise_time(column(r.edited, 1)), rise_time(column(r.nominal, 1)));
}

TEST(LinearPlant, TimeConstantEditOnContinuousChannelRescalesTimeKeepingDeadTime) {
  const PlantModel m = example_plant("wood-berry-continuous.yaml");
  const DiscreteTf tf =
      edited_channel(m.channel(1, 0), {.output = "y2", .input = "u1", .time_constant_factor = 0.7}, 1.0);
  const DiscreteTf expected = discretize_zoh(ContinuousTf{{6.6}, {10.9 * 0.7, 1.0}, 7.0}, 1.0);
  ASSERT_EQ(tf.num.size(), expected.num.size());
  for (std::size_t i = 0; i < tf.num.size(); ++i) EXPECT_NEAR(tf.num[i], expected.num[i], 1e-12);
  EXPECT_NEAR(tf.den[1], expected.den[1], 1e-12);
  EXPECT_EQ(tf.delay, expected.delay);
}

TEST(LinearPlant, ExtraLagKeepsGainAndSlowsTheChannel) {
  const PlantModel m = example_plant("wood-berry.yaml");
  const auto r = responses(m, one_edit({.output = "y1", .input = "u1", .extra_lag_pole = 0.6}), {1.0, 0.0});
  EXPECT_NEAR(r.edited.back()[0], r.nominal.back()[0], 1e-6);
  EXPECT_GT(rise_time(column(r.edited, 0)), rise_time(column(r.nominal, 0)));
  for (std::size_t k = 3; k < 40; ++k) EXPECT_LT(r.edited[k][0], r.nominal[k][0]) << k;
}

TEST(LinearPlant, IntegratorEditTurnsTheStepResponseIntoARamp) {
  const PlantModel m = example_plant("quad-tank-4x4.yaml");
  Plant p = build(m, one_edit({.output = "y3", .input = "u2", .add_integrator = true}));
  const auto y = step_response(p, {0.0, 1.0, 0.0, 0.0}, 200);
  // G32 = 0.078/(0.028 s + 0.25) is static at Ts = 2 s: G32/s ramps at 0.312/s.
  EXPECT_NEAR(y[199][2] - y[198][2], 0.312 * 2.0, 1e-6);
  EXPECT_NEAR(y[100][2] - y[99][2], 0.312 * 2.0, 1e-6);
}

TEST(LinearPlant, MissingChannelIsAdded) {
  const PlantModel m = example_plant("quad-tank-4x4.yaml");
  const ChannelEdit added{.output = "y3", .input = "u3", .replace_continuous = ContinuousTf{{0.2}, {1.0, 0.02}, 0.0}};
  const auto r = responses(m, one_edit(added), {0.0, 0.0, 1.0, 0.0});
  EXPECT_EQ(r.nominal[399][2], 0.0);        // model: u3 does nothing to y3
  EXPECT_NEAR(r.edited[399][2], 10.0 * (1 - std::exp(-0.02 * 2 * 399)), 1e-6);  // 0.2/(s+0.02): gain 10
}

TEST(LinearPlant, EditsOfUnknownSignalsOrTwiceTheSameChannelAreRejected) {
  const PlantModel m = example_plant("wood-berry.yaml");
  EXPECT_THROW(build(m, one_edit({.output = "y9", .input = "u1"})), std::invalid_argument);
  PlantSpec twice;
  twice.channels = {{.output = "y1", .input = "u1"}, {.output = "y1", .input = "u1"}};
  EXPECT_THROW(build(m, twice), std::invalid_argument);
  EXPECT_THROW(build(m, one_edit({.output = "y1", .input = "u1", .extra_lag_pole = 1.0})), std::invalid_argument);
}

TEST(Instruments, ActuatorLagSlowsEveryChannelOfThatInputAlike) {
  const PlantModel m = example_plant("wood-berry.yaml");
  const PlantSpec spec = one_edit(InputEdit{.input = "u2", .actuator_lag_pole = 0.45});
  const auto r = responses(m, spec, {0.0, 1.0});
  // Each edited response is the nominal one through (1-p)/(1-p q^-1).
  for (std::size_t j = 0; j < 2; ++j) {
    double filtered = 0.0;
    for (std::size_t k = 0; k < kN; ++k) {
      filtered = 0.45 * filtered + 0.55 * r.nominal[k][j];
      EXPECT_NEAR(r.edited[k][j], filtered, 1e-12) << "output " << j << " k " << k;
    }
    EXPECT_NEAR(r.edited.back()[j], r.nominal.back()[j], 1e-6);
  }
  // u1's column is untouched.
  const auto r1 = responses(m, spec, {1.0, 0.0});
  for (std::size_t k = 0; k < kN; ++k) EXPECT_EQ(r1.edited[k][1], r1.nominal[k][1]);
}

TEST(Instruments, SaturationClipsTheEffectiveInput) {
  const PlantModel m = example_plant("wood-berry.yaml");
  const PlantSpec spec = one_edit(InputEdit{.input = "u1", .upper_limit = 0.9});
  const auto big = responses(m, spec, {2.0, 0.0});
  EXPECT_NEAR(big.edited.back()[0] / big.nominal.back()[0], 0.9 / 2.0, 1e-9);
  const auto small = responses(m, spec, {0.5, 0.0});  // inside the limit: no effect
  for (std::size_t k = 0; k < kN; ++k) EXPECT_EQ(small.edited[k][0], small.nominal[k][0]);
  const auto down = responses(m, spec, {-2.0, 0.0});  // no lower limit given
  EXPECT_EQ(down.edited.back()[0], down.nominal.back()[0]);
}

TEST(Instruments, DeadbandIgnoresSmallMovesAndLosesHalfTheBandOnLargeOnes) {
  const PlantModel m = example_plant("wood-berry.yaml");
  const PlantSpec spec = one_edit(InputEdit{.input = "u2", .deadband_width = 0.5});
  const auto small = responses(m, spec, {0.0, 0.2});
  for (std::size_t k = 0; k < kN; ++k) {
    EXPECT_EQ(small.edited[k][0], 0.0);
    EXPECT_EQ(small.edited[k][1], 0.0);
  }
  const auto large = responses(m, spec, {0.0, 1.0});
  EXPECT_NEAR(large.edited.back()[1] / large.nominal.back()[1], 0.75, 1e-9);

  // A reversal smaller than the band does nothing either (hysteresis): the
  // plant behaves as if the command had stayed at 1.
  Plant p = build(m, spec), held = build(m, spec);
  std::vector<double> y(2), y_held(2), zero(2, 0.0);
  for (int k = 0; k < 600; ++k) {
    p.measure(zero.data(), y.data());
    held.measure(zero.data(), y_held.data());
    EXPECT_EQ(y[1], y_held[1]) << k;
    const double u[2] = {0.0, k < 300 ? 1.0 : 0.6};  // back by 0.4 < 0.5
    const double u_held[2] = {0.0, 1.0};
    p.apply(u, nullptr);
    held.apply(u_held, nullptr);
  }
}

TEST(Instruments, SensorLagFiltersEveryChannelIntoThatOutputAndTheNoise) {
  const PlantModel m = example_plant("wood-berry.yaml");
  PlantSpec spec;
  spec.outputs = {OutputEdit{"y1", 0.5}};
  Plant nominal = build(m), lagged = build(m, spec);
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n01;
  std::vector<double> a(2), b(2), d(2), u(2);
  double filtered = 0.0;
  for (int k = 0; k < 500; ++k) {
    d = {n01(rng), n01(rng)};
    u = {n01(rng), n01(rng)};
    nominal.measure(d.data(), a.data());
    lagged.measure(d.data(), b.data());
    filtered = 0.5 * filtered + 0.5 * a[0];
    EXPECT_NEAR(b[0], filtered, 1e-12);
    EXPECT_EQ(b[1], a[1]);  // y2's transmitter is ideal
    nominal.apply(u.data(), nullptr);
    lagged.apply(u.data(), nullptr);
  }
}

}  // namespace
}  // namespace mpm::sim
