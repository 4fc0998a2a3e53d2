// The scenario registry: the required names exist, every scenario runs on its
// default plant, each mismatch changes the run, built-in plant copies equal
// the files under config/.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "config/plant_loader.hpp"
#include "core/mimo_model.hpp"
#include "sim/builtin_plants.hpp"
#include "sim/scenarios.hpp"
#include "sim/sim_test_support.hpp"

namespace mpm::sim {
namespace {

TEST(Scenarios, TheRequiredOnesExistWithSummaries) {
  for (const char* name : {"wood-berry-nominal", "wood-berry-g21-gain", "wood-berry-g21-g12", "quad-tank-g23-order",
                           "quad-tank-g33-zero", "quad-tank-g32-integrator"})
    EXPECT_NE(find_scenario(name), nullptr) << name;
  EXPECT_EQ(find_scenario("no-such-scenario"), nullptr);
  for (const auto& s : scenarios()) {
    EXPECT_FALSE(s.summary.empty()) << s.name;
    EXPECT_EQ(s.summary.find('\n'), std::string::npos) << s.name;
  }
}

// plant-nominal has no default plant: it runs on Wood-Berry here (and on the
// other example plants in test_plant_nominal.cpp).
TEST(Scenarios, EveryScenarioRunsOnItsDefaultPlant) {
  for (const auto& s : scenarios()) {
    const ResolvedPlant plant =
        s.plant_file.empty() ? ResolvedPlant{testing::example_plant("wood-berry.yaml"), "wood-berry.yaml"}
                             : default_plant(s);
    const LoopConfig config = scenario_loop(s, plant.model);
    ClosedLoop loop(plant.model, config, 1);
    const auto rec = simulate(loop, 300);
    EXPECT_TRUE(rec.data.allFinite()) << s.name;
    std::size_t recorded = 0;
    for (const auto& x : config.plant.extra_inputs) recorded += x.recorded ? 1 : 0;
    EXPECT_EQ(rec.names.size(), 1 + plant.model.n_inputs() + 2 * plant.model.n_outputs() + recorded) << s.name;
  }
}

// Same seed: the nominal run and a mismatch run share noise and setpoints,
// so any difference is the mismatch.
TEST(Scenarios, EachMismatchChangesTheRunAndNominalDoesNot) {
  for (const auto& s : scenarios()) {
    if (s.name.rfind("quad-tank-wide-", 0) == 0) continue;  // same plant, other range: next test
    if (s.tune) continue;                           // plant = model by construction (test_plant_nominal.cpp)
    const ResolvedPlant plant = default_plant(s);
    const char* nominal = s.plant_file == "wood-berry.yaml" ? "wood-berry-nominal"
                          : s.plant_file == "quad-tank.yaml" ? "quad-tank-nominal"
                                                             : "quad-tank-4x4-nominal";
    LoopConfig base = find_scenario(nominal)->loop;
    base.setpoints = s.loop.setpoints;  // quad-tank-wide-low moves the setpoints too
    ClosedLoop a(plant.model, s.loop, 2), b(plant.model, base, 2);
    const auto ra = simulate(a, 800), rb = simulate(b, 800);
    const Eigen::Index outputs_from = 1 + static_cast<Eigen::Index>(plant.model.n_inputs());
    const auto ya = ra.data.middleCols(outputs_from, static_cast<Eigen::Index>(plant.model.n_outputs()));
    const auto yb = rb.data.middleCols(outputs_from, static_cast<Eigen::Index>(plant.model.n_outputs()));
    if (s.name == nominal) {
      EXPECT_TRUE(ya == yb) << s.name;
    } else {
      EXPECT_GT((ya - yb).cwiseAbs().maxCoeff(), 1e-3) << s.name;
    }
  }
}

// IMC residual y - G_M (u - u0) of a recording, per output: its mean square.
std::vector<double> residual_power(const PlantModel& m, const config::Recording& rec) {
  ResidualGenerator gen(m, m.operating_point->inputs);
  std::vector<double> power(m.n_outputs(), 0.0), u(m.n_inputs()), y(m.n_outputs()), res(m.n_outputs());
  for (Eigen::Index k = 0; k < rec.data.rows(); ++k) {
    for (std::size_t l = 0; l < u.size(); ++l) u[l] = rec.data(k, static_cast<Eigen::Index>(1 + l));
    for (std::size_t j = 0; j < y.size(); ++j) y[j] = rec.data(k, static_cast<Eigen::Index>(1 + u.size() + j));
    gen.step(u.data(), y.data(), res.data());
    for (std::size_t j = 0; j < y.size(); ++j) {
      const double e = res[j] - m.operating_point->outputs[j];
      power[j] += e * e / static_cast<double>(rec.data.rows());
    }
  }
  return power;
}

// Away from its linearisation point the tank's gain differs from the model's:
// the model residual grows well beyond the noise it has near the point.
TEST(Scenarios, WideRangeQuadTankDepartsFromTheLinearModel) {
  const PlantModel m = default_plant(*find_scenario("quad-tank-nominal")).model;
  ClosedLoop near(m, find_scenario("quad-tank-nominal")->loop, 5);
  const auto p_near = residual_power(m, simulate(near, 2000));
  for (const char* name : {"quad-tank-wide-low", "quad-tank-wide-high"}) {
    ClosedLoop wide(m, find_scenario(name)->loop, 5);
    const auto p_wide = residual_power(m, simulate(wide, 2000));
    for (std::size_t j = 0; j < 2; ++j) EXPECT_GT(p_wide[j], 10.0 * p_near[j]) << name << " output " << j;
  }
}

void expect_same_plant(const PlantModel& a, const PlantModel& b, const std::string& what) {
  EXPECT_EQ(a.name, b.name) << what;
  EXPECT_EQ(a.sample_time, b.sample_time) << what;
  EXPECT_EQ(a.inputs, b.inputs) << what;
  EXPECT_EQ(a.outputs, b.outputs) << what;
  ASSERT_EQ(a.channels.size(), b.channels.size()) << what;
  for (std::size_t c = 0; c < a.channels.size(); ++c) {
    EXPECT_EQ(a.channels[c].tf.num, b.channels[c].tf.num) << what;
    EXPECT_EQ(a.channels[c].tf.den, b.channels[c].tf.den) << what;
    EXPECT_EQ(a.channels[c].tf.delay, b.channels[c].tf.delay) << what;
  }
  ASSERT_EQ(a.noise.size(), b.noise.size()) << what;
  for (std::size_t j = 0; j < a.noise.size(); ++j) {
    ASSERT_EQ(a.noise[j].has_value(), b.noise[j].has_value()) << what;
    if (a.noise[j]) {
      EXPECT_EQ(a.noise[j]->tf.den, b.noise[j]->tf.den) << what;
      EXPECT_EQ(a.noise[j]->variance, b.noise[j]->variance) << what;
    }
  }
  ASSERT_EQ(a.operating_point.has_value(), b.operating_point.has_value()) << what;
  if (a.operating_point) {
    EXPECT_EQ(a.operating_point->inputs, b.operating_point->inputs) << what;
    EXPECT_EQ(a.operating_point->outputs, b.operating_point->outputs) << what;
  }
}

TEST(Scenarios, BuiltInPlantCopiesEqualTheConfigFiles) {
  for (const char* file : {"wood-berry.yaml", "quad-tank.yaml", "quad-tank-4x4.yaml"}) {
    const auto text = builtin_plant_text(file);
    ASSERT_TRUE(text.has_value()) << file;
    expect_same_plant(config::parse_plant(std::string(*text), file), testing::example_plant(file), file);
  }
  EXPECT_FALSE(builtin_plant_text("other.yaml").has_value());
}

TEST(Scenarios, ConfigDirFromTheEnvironmentComesFirst) {
  const std::filesystem::path dir = std::filesystem::path(MPM_BINARY_DIR) / "sim_test_config_dir";
  std::filesystem::create_directories(dir);
  std::string text(*builtin_plant_text("wood-berry.yaml"));
  text.replace(text.find("plant: wood-berry"), 17, "plant: wood-berry-from-env");
  std::ofstream(dir / "wood-berry.yaml") << text;
  ASSERT_EQ(setenv("MPM_CONFIG_DIR", dir.c_str(), 1), 0);
  const ResolvedPlant p = default_plant(*find_scenario("wood-berry-nominal"));
  unsetenv("MPM_CONFIG_DIR");
  EXPECT_EQ(p.model.name, "wood-berry-from-env");
  EXPECT_EQ(p.source, (dir / "wood-berry.yaml").string());
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace mpm::sim
