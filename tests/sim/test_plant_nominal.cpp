// The `plant-nominal` scenario: a loop tuned from the plant model alone. On
// the 2x2, 3x3 and 4x4 example plants it records the plant's columns, tracks
// its setpoints, keeps the inputs off their limits and is deterministic per
// seed; the derived scales follow the model (settling, gains, zero and absent
// channels, integrators, fast plants, a missing noise section).
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "config/plant_loader.hpp"
#include "sim/closed_loop.hpp"
#include "sim/plant_tuning.hpp"
#include "sim/scenarios.hpp"
#include "sim/sim_test_support.hpp"

namespace mpm::sim {
namespace {

using Index = Eigen::Index;
using testing::example_plant;

const char* const kPlants[] = {"wood-berry.yaml", "three-by-three.yaml", "quad-tank-4x4.yaml"};
constexpr std::size_t kSamples = 3000;

const Scenario& plant_nominal() {
  const Scenario* s = find_scenario("plant-nominal");
  if (s == nullptr) throw std::runtime_error("no scenario plant-nominal");
  return *s;
}

struct LoopRun {
  LoopConfig loop;
  config::Recording rec;
  std::size_t constrained = 0;
};

LoopRun run(const PlantModel& m, std::uint64_t seed, double noise_scale = 1.0) {
  LoopRun r;
  r.loop = scenario_loop(plant_nominal(), m);
  r.loop.noise_scale = noise_scale;
  ClosedLoop loop(m, r.loop, seed);
  r.rec = simulate(loop, kSamples);
  r.constrained = loop.controller().constrained_samples();
  return r;
}

Eigen::VectorXd column(const config::Recording& rec, const std::string& name) {
  return rec.data.col(static_cast<Index>(*rec.find(name)));
}

double mean_abs(const Eigen::VectorXd& v) { return v.cwiseAbs().mean(); }

TEST(PlantNominal, IsListedWithoutADefaultPlant) {
  const Scenario& s = plant_nominal();
  EXPECT_TRUE(s.plant_file.empty());
  EXPECT_NE(s.tune, nullptr);
  EXPECT_NE(s.summary.find("any plant file"), std::string::npos) << s.summary;
  try {
    default_plant(s);
    ADD_FAILURE() << "default_plant should refuse plant-nominal";
  } catch (const config::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("--plant"), std::string::npos) << e.what();
  }
}

TEST(PlantNominal, RecordsThePlantsColumns) {
  for (const char* file : kPlants) {
    const PlantModel m = example_plant(file);
    const LoopRun r = run(m, 1);
    std::vector<std::string> expected{"t"};
    expected.insert(expected.end(), m.inputs.begin(), m.inputs.end());
    expected.insert(expected.end(), m.outputs.begin(), m.outputs.end());
    for (const auto& y : m.outputs) expected.push_back("r_" + y);
    EXPECT_EQ(r.rec.names, expected) << file;
    EXPECT_EQ(r.rec.data.rows(), static_cast<Index>(kSamples)) << file;
    EXPECT_TRUE(r.rec.data.allFinite()) << file;
  }
}

// Without noise the outputs follow their setpoints closely; with the file's
// noise the error is the noise's, still well below the steps. Every output's
// setpoint does step (so the run has excitation).
TEST(PlantNominal, OutputsTrackTheirSetpoints) {
  for (const char* file : kPlants) {
    const PlantModel m = example_plant(file);
    const LoopRun clean = run(m, 1, 0.0), noisy = run(m, 1);
    for (std::size_t j = 0; j < m.n_outputs(); ++j) {
      const std::string& y = m.outputs[j];
      const double a = clean.loop.setpoints[j].random_amplitude;
      ASSERT_GT(a, 0.0) << file << " " << y;
      const Eigen::VectorXd r = column(clean.rec, "r_" + y);
      const double spread = mean_abs(r.array() - r.mean());
      EXPECT_GT(r.maxCoeff() - r.minCoeff(), 0.2 * a) << file << " " << y << ": the setpoint hardly moved";
      const double clean_error = mean_abs(column(clean.rec, y) - r);
      EXPECT_LT(clean_error, 0.1 * a) << file << " " << y;
      EXPECT_LT(clean_error, 0.25 * spread) << file << " " << y;
      EXPECT_LT(mean_abs(column(noisy.rec, y) - column(noisy.rec, "r_" + y)), 0.35 * a) << file << " " << y;
    }
  }
}

// The limits rarely bind (the QP ran at under 2 % of the samples, warm-up
// included), no input sits at a limit, and every input moves by a visible
// but modest amount.
TEST(PlantNominal, InputsMoveButStayOffTheirLimits) {
  for (const char* file : kPlants) {
    const PlantModel m = example_plant(file);
    const LoopRun r = run(m, 1);
    const double samples = static_cast<double>(kSamples) + static_cast<double>(r.loop.warmup);
    EXPECT_LT(static_cast<double>(r.constrained), 0.02 * samples) << file;
    const std::vector<double> u0 = m.operating_point ? m.operating_point->inputs : std::vector<double>(m.n_inputs());
    for (std::size_t l = 0; l < m.n_inputs(); ++l) {
      const Eigen::ArrayXd u = column(r.rec, m.inputs[l]).array() - u0[l];
      const double limit = r.loop.mpc.input_upper[l];
      ASSERT_DOUBLE_EQ(r.loop.mpc.input_lower[l], -limit) << file;
      const double at_limit = (u.abs() >= 0.99 * limit).cast<double>().mean();
      EXPECT_LT(at_limit, 0.02) << file << " " << m.inputs[l];
      const double std = std::sqrt((u - u.mean()).square().mean());
      EXPECT_GT(std, 0.1) << file << " " << m.inputs[l];
      EXPECT_LT(std, 0.25 * limit) << file << " " << m.inputs[l];
    }
  }
}

TEST(PlantNominal, SameSeedSameRecording) {
  const PlantModel m = example_plant("three-by-three.yaml");
  const auto a = run(m, 7).rec, b = run(m, 7).rec, c = run(m, 8).rec;
  EXPECT_TRUE(a.data == b.data);
  EXPECT_FALSE(a.data == c.data);
}

// Wood-Berry's slowest channel, G12 = -0.8789 q^-4/(1 - 0.9535 q^-1), is
// within 1 % after 4 + ln(0.01)/ln(0.9535) = 101 samples; the continuous
// form of the same plant settles alike. Gains are the channels' DC gains.
TEST(PlantScales, SettlingAndGainsFollowTheModel) {
  const PlantScales s = plant_scales(example_plant("wood-berry.yaml"));
  EXPECT_NEAR(static_cast<double>(s.settling), 101.0, 2.0);
  EXPECT_EQ(s.horizon, s.settling);
  EXPECT_NEAR(s.gain(0, 0), 0.744 / (1 - 0.9419), 1e-9);
  EXPECT_NEAR(s.gain(1, 1), -1.302 / (1 - 0.9329), 1e-9);
  const PlantScales c = plant_scales(example_plant("wood-berry-continuous.yaml"));
  EXPECT_NEAR(static_cast<double>(c.settling), static_cast<double>(s.settling), 2.0);
  // The setpoint steps need input moves of 1 unit RMS, geometric mean.
  double log_mean = 0.0;
  for (double b : s.move) log_mean += std::log(b) / static_cast<double>(s.move.size());
  EXPECT_NEAR(log_mean, 0.0, 1e-12);
}

// The 3x3's y1 <- u3 is absent and y3 <- u1 an explicit zero: both count as
// zero gain, and every output and input still gets steps and weights.
TEST(PlantScales, ZeroAndAbsentChannelsHaveNoGain) {
  const PlantModel m = example_plant("three-by-three.yaml");
  const PlantScales s = plant_scales(m);
  EXPECT_EQ(s.gain(0, 2), 0.0);
  EXPECT_EQ(s.gain(2, 0), 0.0);
  EXPECT_NEAR(s.gain(2, 2), 1.2, 1e-6);
  const LoopConfig c = tuned_loop(m);
  for (double q : c.mpc.output_weights) EXPECT_GT(q, 0.0);
  for (double r : c.mpc.move_weights) EXPECT_GT(r, 0.0);
  EXPECT_EQ(c.mpc.prediction_horizon, static_cast<std::size_t>(s.horizon));
  EXPECT_GE(c.mpc.control_horizon, 5u);
  EXPECT_LE(c.mpc.control_horizon, 10u);
  EXPECT_GE(c.setpoints[0].random_period_min, 3 * s.horizon);
  EXPECT_GT(c.warmup, 0);
}

PlantModel siso(DiscreteTf tf) {
  PlantModel m;
  m.name = "siso";
  m.inputs = {"u"};
  m.outputs = {"y"};
  m.channels = {ChannelModel{0, 0, std::move(tf), false, std::nullopt}};
  m.noise = {std::nullopt};
  return m;
}

// A fast plant gets the shortest horizon; without a noise section the noise
// is white with a tenth of the setpoint step as its std.
TEST(PlantScales, FastPlantWithoutNoiseSection) {
  const PlantModel m = siso(DiscreteTf{{0.5}, {1.0, -0.5}, 1});
  const PlantScales s = plant_scales(m);
  EXPECT_LT(s.settling, 20);
  EXPECT_EQ(s.horizon, 20);
  const LoopConfig c = tuned_loop(m);
  const double a = c.setpoints[0].random_amplitude;
  EXPECT_NEAR(c.default_noise_variance, 0.01 * a * a, 1e-12);
  EXPECT_NEAR(s.noise_std[0], 0.1 * a, 1e-9);
}

// An integrating channel counts with its slope times the horizon, and the
// loop around it tracks.
TEST(PlantScales, IntegratingChannelRunsInClosedLoop) {
  const PlantModel m = siso(DiscreteTf{{0.1}, {1.0, -1.0}, 2});
  const PlantScales s = plant_scales(m);
  EXPECT_NEAR(s.gain(0, 0), 0.1 * static_cast<double>(s.horizon), 1e-9);
  const LoopRun r = run(m, 3, 0.0);
  const double a = r.loop.setpoints[0].random_amplitude;
  EXPECT_TRUE(r.rec.data.allFinite());
  EXPECT_LT(mean_abs(column(r.rec, "y") - column(r.rec, "r_y")), 0.1 * a);
}

}  // namespace
}  // namespace mpm::sim
