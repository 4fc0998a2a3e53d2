// The nonlinear quadruple tank: rests at its operating point, and for small
// steps behaves like the linearised model in config/quad-tank.yaml.
#include <gtest/gtest.h>

#include <cmath>

#include "sim/linear_process.hpp"
#include "sim/quad_tank.hpp"
#include "sim/sim_test_support.hpp"

namespace mpm::sim {
namespace {

TEST(QuadTank, OperatingPointIsJohanssonsMinimumPhaseSetting) {
  const QuadTankParams p;
  const auto h = steady_levels(p, p.pump_voltage);
  // Johansson (2000), Table 2, P-: h0 = (12.4, 12.7, 1.8, 1.4) cm with its
  // rounded parameters; with k = (3.33, 3.35) exactly these levels follow.
  EXPECT_NEAR(h[0], 12.263, 1e-3);
  EXPECT_NEAR(h[1], 12.783, 1e-3);
  EXPECT_NEAR(h[2], 1.634, 1e-3);
  EXPECT_NEAR(h[3], 1.409, 1e-3);
  const auto rates = level_rates(p, h, p.pump_voltage);
  for (double r : rates) EXPECT_NEAR(r, 0.0, 1e-12);
}

TEST(QuadTank, StaysAtItsOperatingPointWithConstantInputs) {
  QuadTankProcess tank(QuadTankParams{}, 5.0);
  const double u[2] = {0.0, 0.0};
  double y[2];
  for (int k = 0; k < 2000; ++k) tank.advance(u);
  tank.output(y);
  EXPECT_NEAR(y[0], 0.0, 1e-9);
  EXPECT_NEAR(y[1], 0.0, 1e-9);
}

TEST(QuadTank, ConfigFileIsItsLinearisation) {
  const PlantModel file = testing::example_plant("quad-tank.yaml");
  const PlantModel lin = linearised_quad_tank(QuadTankParams{}, 5.0);
  ASSERT_EQ(file.channels.size(), lin.channels.size());
  EXPECT_EQ(file.sample_time, lin.sample_time);
  for (std::size_t c = 0; c < lin.channels.size(); ++c) {
    const ContinuousTf& a = *file.channels[c].continuous;
    const ContinuousTf& b = *lin.channels[c].continuous;
    ASSERT_EQ(a.num.size(), b.num.size());
    ASSERT_EQ(a.den.size(), b.den.size());
    for (std::size_t i = 0; i < a.num.size(); ++i) EXPECT_NEAR(a.num[i], b.num[i], 1e-8 * std::abs(b.num[i]));
    for (std::size_t i = 0; i < a.den.size(); ++i) EXPECT_NEAR(a.den[i], b.den[i], 1e-8 * std::abs(b.den[i]) + 1e-12);
  }
  for (std::size_t j = 0; j < 2; ++j) {
    EXPECT_NEAR(file.operating_point->outputs[j], lin.operating_point->outputs[j], 1e-8);
    EXPECT_EQ(file.operating_point->inputs[j], lin.operating_point->inputs[j]);
  }
}

// A 0.1 V pump step (3 % of the operating point) through both.
void expect_small_step_matches_linear(std::size_t input) {
  const PlantModel lin = linearised_quad_tank(QuadTankParams{}, 5.0);
  QuadTankProcess tank(QuadTankParams{}, 5.0);
  std::vector<LinearChannel> channels;
  for (const auto& c : lin.channels) channels.push_back({c.output, c.input, c.tf});
  LinearProcess model(2, 2, channels);
  double u[2] = {0.0, 0.0};
  u[input] = 0.1;
  double yt[2], ym[2], final_model[2];
  std::vector<std::array<double, 4>> traj;
  for (int k = 0; k < 400; ++k) {  // 2000 s: settled
    tank.output(yt);
    model.output(ym);
    traj.push_back({yt[0], yt[1], ym[0], ym[1]});
    tank.advance(u);
    model.advance(u);
  }
  model.output(final_model);
  for (std::size_t j = 0; j < 2; ++j) {
    const double scale = std::abs(final_model[j]);
    ASSERT_GT(scale, 0.01);
    double worst = 0.0;
    for (const auto& row : traj) worst = std::max(worst, std::abs(row[j] - row[2 + j]));
    EXPECT_LT(worst / scale, 0.03) << "input " << input << " output " << j;
    EXPECT_GT(worst / scale, 1e-5) << "the plant is nonlinear: not identical";  // it is a different code path
  }
}

TEST(QuadTank, SmallStepResponseMatchesTheLinearisedModel) {
  expect_small_step_matches_linear(0);
  expect_small_step_matches_linear(1);
}

TEST(QuadTank, LargeStepShowsTheNonlinearGain) {
  // At rest h grows with v^2 (outflow ~ sqrt h), so going from 3 V to 2 V on
  // both pumps the level falls by 5/9 h0 where the tangent (the linear model)
  // says 2/3 h0: 5/6 of the linear prediction.
  const PlantModel lin = linearised_quad_tank(QuadTankParams{}, 5.0);
  QuadTankProcess tank(QuadTankParams{}, 5.0);
  const double u[2] = {-1.0, -1.0};
  for (int k = 0; k < 1000; ++k) tank.advance(u);
  double y[2];
  tank.output(y);
  const double linear = -(lin.channels[0].tf.dc_gain() + lin.channels[1].tf.dc_gain());
  EXPECT_NEAR(y[0] / linear, 5.0 / 6.0, 1e-3);
}

TEST(QuadTank, RejectsBadParameters) {
  QuadTankParams p;
  p.valve_split[0] = 1.2;
  EXPECT_THROW(QuadTankProcess(p, 5.0), std::invalid_argument);
  EXPECT_THROW(QuadTankProcess(QuadTankParams{}, 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace mpm::sim
