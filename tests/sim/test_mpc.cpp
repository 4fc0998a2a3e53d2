// DMC with IMC bias correction: tracks with a matched model, rejects an
// unmeasured step disturbance, honours the input limits, and its first move is
// the textbook least-squares DMC move.
#include <gtest/gtest.h>

#include <cmath>
#include <utility>
#include <vector>

#include "core/transfer_function.hpp"
#include "sim/mpc.hpp"
#include "sim/sim_test_support.hpp"

namespace mpm::sim {
namespace {

using testing::build;
using testing::example_plant;

MpcSettings table2() {
  MpcSettings s;
  s.prediction_horizon = 100;
  s.control_horizon = 10;
  s.output_weights = {1.0, 50.0};
  s.move_weights = {1.0, 2.0};
  return s;
}

// Table 2 with input limits.
MpcSettings table2(std::vector<double> lower, std::vector<double> upper) {
  MpcSettings s = table2();
  s.input_lower = std::move(lower);
  s.input_upper = std::move(upper);
  return s;
}

// Wood-Berry's steady-state gains G(1) (wood-berry.yaml).
constexpr double kG11 = 0.744 / (1 - 0.9419), kG12 = -0.8789 / (1 - 0.9535);
constexpr double kG21 = 0.5786 / (1 - 0.9123), kG22 = -1.302 / (1 - 0.9329);

// Runs plant + controller for n samples with setpoint r and an output
// disturbance d_from_k (added from sample k_d on); returns the last y and u
// and the extreme inputs seen.
struct LoopResult {
  std::vector<double> y, u, u_min, u_max;
};

LoopResult run_loop(const PlantModel& m, DmcController& mpc, const std::vector<double>& r, int n,
        const std::vector<double>& disturbance = {}, int k_d = 0) {
  Plant plant = build(m);
  LoopResult out{std::vector<double>(m.n_outputs()), std::vector<double>(m.n_inputs()),
          std::vector<double>(m.n_inputs(), 1e300), std::vector<double>(m.n_inputs(), -1e300)};
  std::vector<double> d(m.n_outputs(), 0.0);
  for (int k = 0; k < n; ++k) {
    if (!disturbance.empty() && k >= k_d) d = disturbance;
    plant.measure(d.data(), out.y.data());
    mpc.step(out.y.data(), r.data(), out.u.data());
    for (std::size_t l = 0; l < out.u.size(); ++l) {
      out.u_min[l] = std::min(out.u_min[l], out.u[l]);
      out.u_max[l] = std::max(out.u_max[l], out.u[l]);
    }
    plant.apply(out.u.data(), nullptr);
  }
  return out;
}

TEST(Dmc, MatchedModelTracksASetpointStep) {
  const PlantModel m = example_plant("wood-berry.yaml");
  DmcController mpc(m, table2());
  const LoopResult r = run_loop(m, mpc, {1.0, -0.5}, 400);
  EXPECT_NEAR(r.y[0], 1.0, 1e-4);
  EXPECT_NEAR(r.y[1], -0.5, 1e-4);
  EXPECT_EQ(mpc.constrained_samples(), 0u);
  // Steady state inputs solve G(1) u = r.
  EXPECT_NEAR(kG11 * r.u[0] + kG12 * r.u[1], 1.0, 1e-4);
  EXPECT_NEAR(kG21 * r.u[0] + kG22 * r.u[1], -0.5, 1e-4);
}

TEST(Dmc, BiasCorrectionRemovesAnUnmeasuredStepDisturbance) {
  const PlantModel m = example_plant("wood-berry.yaml");
  DmcController mpc(m, table2());
  const LoopResult r = run_loop(m, mpc, {0.0, 0.0}, 600, {2.0, -1.0}, 50);
  EXPECT_NEAR(r.y[0], 0.0, 1e-4);
  EXPECT_NEAR(r.y[1], 0.0, 1e-4);
}

TEST(Dmc, TracksOnTheFourByFourModelWithSecondOrderAndZeroChannels) {
  const PlantModel m = example_plant("quad-tank-4x4.yaml");
  MpcSettings s;
  s.move_weights = {10.0, 10.0, 10.0, 10.0};
  DmcController mpc(m, s);
  const LoopResult r = run_loop(m, mpc, {15.0, 0.0, 0.0, 5.0}, 1500);
  EXPECT_NEAR(r.y[0], 15.0, 1e-3);
  EXPECT_NEAR(r.y[1], 0.0, 1e-3);
  EXPECT_NEAR(r.y[2], 0.0, 1e-3);
  EXPECT_NEAR(r.y[3], 5.0, 1e-3);
}

TEST(Dmc, HonoursInputLimits) {
  const PlantModel m = example_plant("wood-berry.yaml");
  const MpcSettings s = table2({-0.3, -0.2}, {0.3, 0.25});
  DmcController mpc(m, s);
  // Unconstrained, this setpoint needs u = (0.85, 0.55) or so.
  const LoopResult r = run_loop(m, mpc, {3.0, 1.0}, 600);
  EXPECT_GT(mpc.constrained_samples(), 100u);
  for (std::size_t l = 0; l < 2; ++l) {
    EXPECT_GE(r.u_min[l], s.input_lower[l] - 1e-12);
    EXPECT_LE(r.u_max[l], s.input_upper[l] + 1e-12);
  }
  // The limits bind at the end: the outputs are as close as the box allows.
  EXPECT_NEAR(r.u[0], 0.3, 1e-9);
  EXPECT_EQ(mpc.fallback_samples(), 0u);
}

TEST(Dmc, InputLimitsBindWhereClippingWouldBeWorse) {
  // With u1 pinned at its limit, the QP re-plans u2; clipping the
  // unconstrained move would not. Compare the y2 error after the transient.
  const PlantModel m = example_plant("wood-berry.yaml");
  const MpcSettings s = table2({-0.2, -10.0}, {0.2, 10.0});
  DmcController mpc(m, s);
  const LoopResult r = run_loop(m, mpc, {2.0, 0.0}, 800);
  EXPECT_NEAR(r.u[0], 0.2, 1e-9);
  // With u1 at 0.2, y2 = 0 needs u2 = -g21 u1 / g22 exactly (weight 50 on y2).
  const double y2 = kG21 * r.u[0] + kG22 * r.u[1];
  const double y1 = kG11 * r.u[0] + kG12 * r.u[1];
  EXPECT_NEAR(r.y[1], y2, 1e-6);
  EXPECT_NEAR(r.y[0], y1, 1e-6);
  // Weighted steady-state optimum over u2 alone: minimise (2 - y1)^2 + 50 y2^2.
  const double a1 = kG12, b1 = 2.0 - kG11 * 0.2, a2 = kG22, b2 = -kG21 * 0.2;
  const double u2_best = (a1 * b1 + 50.0 * a2 * b2) / (a1 * a1 + 50.0 * a2 * a2);
  EXPECT_NEAR(r.u[1], u2_best, 1e-4);
}

// Independent DMC: dynamic matrix from filter step responses, normal
// equations for the moves, first move compared with the controller's.
TEST(Dmc, FirstMoveIsTheLeastSquaresDmcMove) {
  const PlantModel m = example_plant("wood-berry.yaml");
  const MpcSettings s = table2();
  const int p = 100, mm = 10;
  Eigen::MatrixXd step = Eigen::MatrixXd::Zero(4, p + 1);  // (j*2+l, n)
  for (const auto& c : m.channels) {
    DiscreteFilter f(c.tf);
    for (int n = 0; n <= p; ++n) step(static_cast<Eigen::Index>(c.output * 2 + c.input), n) = f.step(1.0);
  }
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(2 * p, 2 * mm);
  Eigen::VectorXd w(2 * p), e(2 * p);
  for (int i = 1; i <= p; ++i)
    for (int j = 0; j < 2; ++j) {
      w((i - 1) * 2 + j) = s.output_weights[static_cast<std::size_t>(j)];
      e((i - 1) * 2 + j) = j == 0 ? 1.0 : 0.0;  // r = (1, 0), free response 0
      for (int k = 0; k < mm && k <= i; ++k)
        for (int l = 0; l < 2; ++l) a((i - 1) * 2 + j, k * 2 + l) = step(j * 2 + l, i - k);
    }
  Eigen::VectorXd rw(2 * mm);
  for (int k = 0; k < 2 * mm; ++k) rw(k) = s.move_weights[static_cast<std::size_t>(k % 2)];
  const Eigen::MatrixXd h = a.transpose() * w.asDiagonal() * a + Eigen::MatrixXd(rw.asDiagonal());
  const Eigen::VectorXd moves = h.ldlt().solve(a.transpose() * w.asDiagonal() * e);

  DmcController mpc(m, s);
  const double y[2] = {0.0, 0.0}, r[2] = {1.0, 0.0};
  double u[2];
  mpc.step(y, r, u);
  EXPECT_NEAR(u[0], moves(0), 1e-9);
  EXPECT_NEAR(u[1], moves(1), 1e-9);
}

TEST(Dmc, StepResponsesSettleAndExtrapolate) {
  const PlantModel m = example_plant("wood-berry.yaml");
  StepResponses s(m, 102, 1e-10, 50000);
  EXPECT_GE(s.length(), 102u);
  EXPECT_LT(s.length(), 2000u);
  const double g12 = -0.8789 / (1 - 0.9535);
  EXPECT_NEAR(s.at(0, 1, s.length() - 1), g12, 1e-6 * std::abs(g12));
  EXPECT_NEAR(s.at(0, 1, 100000), g12, 1e-6 * std::abs(g12));

  // An integrating model channel: the response keeps its final slope.
  PlantModel integ = m;
  integ.channels[0].tf = DiscreteTf{{0.5}, {1.0, -1.0}, 1};
  StepResponses r(integ, 102, 1e-10, 50000);
  const std::size_t n = r.length() + 500;
  EXPECT_NEAR(r.at(0, 0, n), 0.5 * static_cast<double>(n), 1e-6);
  EXPECT_TRUE(r.ramps(0));
  EXPECT_FALSE(r.ramps(1));
  EXPECT_FALSE(s.ramps(0));
}

TEST(Dmc, RejectsBadSettingsAndUnstableModels) {
  const PlantModel m = example_plant("wood-berry.yaml");
  MpcSettings s = table2();
  s.control_horizon = 200;
  EXPECT_THROW(DmcController(m, s), std::invalid_argument);
  s = table2();
  s.output_weights = {1.0};
  EXPECT_THROW(DmcController(m, s), std::invalid_argument);
  s = table2();
  s.move_weights = {1.0, 0.0};
  EXPECT_THROW(DmcController(m, s), std::invalid_argument);
  EXPECT_THROW(DmcController(m, table2({1.0, 0.0}, {0.0, 1.0})), std::invalid_argument);
  PlantModel unstable = m;
  unstable.channels[0].tf.den = {1.0, -1.01};
  EXPECT_THROW(DmcController(unstable, table2()), std::invalid_argument);
}

}  // namespace
}  // namespace mpm::sim
