// `mpm diagnose --write-plant`: the corrected plant file holds the accepted
// corrections (composed in the order they were accepted, continuous form
// kept where the change is exact in it), reads back through the plant
// loader, never overwrites an input, and a recording diagnosed again with
// it shows no mismatch left on the corrected channel.
#include <cmath>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "config/plant_loader.hpp"
#include "core/diagnosis_signal.hpp"
#include "daemon/plant_writer.hpp"
#include "support/cli.hpp"

namespace {

using mpm::test::kMpm;
using mpm::test::read_file;

const std::string kWoodBerry = std::string(MPM_SOURCE_DIR) + "/config/wood-berry.yaml";
const std::string kWoodBerryContinuous = std::string(MPM_SOURCE_DIR) + "/config/wood-berry-continuous.yaml";

std::string tmp(const std::string& name) { return mpm::test::per_test_tmp_path("mpm_wp_", name); }

const mpm::ChannelModel& channel(const mpm::PlantModel& p, std::size_t j, std::size_t i) {
  const mpm::ChannelModel* c = p.channel(j, i);
  if (!c) throw std::runtime_error("no channel");
  return *c;
}

void expect_tf_near(const mpm::DiscreteTf& a, const mpm::DiscreteTf& b) {
  ASSERT_EQ(a.delay, b.delay);
  ASSERT_EQ(a.num.size(), b.num.size());
  ASSERT_EQ(a.den.size(), b.den.size());
  for (std::size_t k = 0; k < a.num.size(); ++k) EXPECT_NEAR(a.num[k], b.num[k], 1e-8 * (1 + std::abs(b.num[k])));
  for (std::size_t k = 0; k < a.den.size(); ++k) EXPECT_NEAR(a.den[k], b.den[k], 1e-8 * (1 + std::abs(b.den[k])));
}

mpm::diagnosis::Finding finding(std::string physics, std::vector<mpm::diagnosis::Channel> channels,
                                std::map<std::string, double> parameters) {
  mpm::diagnosis::Finding f;
  f.physics = std::move(physics);
  f.channels = std::move(channels);
  f.parameters = std::move(parameters);
  f.summary = "planted " + f.physics;
  f.fit = {2.0, 1.0, 2.0, 1.5};
  f.lr = 99.0;
  f.params = 1;
  return f;
}

TEST(WritePlant, ComposesFindingsAndReadsBack) {
  const mpm::PlantModel nominal = mpm::config::load_plant(kWoodBerryContinuous);
  mpm::diagnosis::Result r;
  r.mismatch = true;
  auto gain = finding("gain", {{1, 0}}, {{"gain_factor", 1.5}});
  gain.fitted = channel(nominal, 1, 0).tf;
  r.findings.push_back(gain);
  auto delay = finding("dead_time", {{0, 1}}, {{"extra_delay_samples", 2}});
  delay.fitted = channel(nominal, 0, 1).tf;
  r.findings.push_back(delay);
  auto actuator = finding("actuator_dynamics", {{0, 0}, {1, 0}}, {{"actuator_lag_pole", 0.6}});
  actuator.fitted = channel(nominal, 0, 0).tf;
  r.findings.push_back(actuator);
  auto saturation = finding("saturation", {{0, 1}, {1, 1}}, {{"upper_limit", 13.0}});
  saturation.fitted = channel(nominal, 0, 1).tf;
  r.findings.push_back(saturation);

  const mpm::CorrectedPlant c = mpm::apply_findings(nominal, r);
  EXPECT_EQ(c.changes, 3u);
  ASSERT_EQ(c.not_applied.size(), 1u);
  const std::string yaml = mpm::plant_yaml(c, kWoodBerryContinuous, "run.csv");
  EXPECT_NE(yaml.find("NOT applied (the plant format cannot express it): saturation"), std::string::npos);
  EXPECT_NE(yaml.find("held-out prediction-error variance 2 -> 1.5 (25 % less)"), std::string::npos) << yaml;
  const std::string path = tmp("corrected.yaml");
  mpm::write_text_file(path, yaml, {kWoodBerryContinuous});
  const mpm::PlantModel back = mpm::config::load_plant(path);

  // y1 <- u2: two more samples of dead time, still continuous (exact).
  ASSERT_TRUE(channel(back, 0, 1).continuous.has_value());
  EXPECT_DOUBLE_EQ(channel(back, 0, 1).continuous->dead_time, channel(nominal, 0, 1).continuous->dead_time + 2.0);
  expect_tf_near(channel(back, 0, 1).tf, [&] {
    mpm::DiscreteTf t = channel(nominal, 0, 1).tf;
    t.delay += 2;
    return t;
  }());
  // y2 <- u1: gain x 1.5, then the actuator lag in series (discrete form).
  mpm::DiscreteTf g21 = channel(nominal, 1, 0).tf;
  for (double& b : g21.num) b *= 1.5;
  expect_tf_near(channel(back, 1, 0).tf, mpm::diagnosis::series(g21, mpm::diagnosis::unit_lag(0.6)));
  EXPECT_FALSE(channel(back, 1, 0).continuous.has_value());
  // y1 <- u1: the actuator lag alone. y2 <- u2: untouched, still continuous.
  expect_tf_near(channel(back, 0, 0).tf, mpm::diagnosis::series(channel(nominal, 0, 0).tf, mpm::diagnosis::unit_lag(0.6)));
  ASSERT_TRUE(channel(back, 1, 1).continuous.has_value());
  expect_tf_near(channel(back, 1, 1).tf, channel(nominal, 1, 1).tf);
  ASSERT_TRUE(back.operating_point.has_value() == nominal.operating_point.has_value());
}

// A gain finding over a column carries one factor per channel
// (gain_factor_<output>): each channel is scaled by its own.
TEST(WritePlant, ColumnGainsScaleEachChannelByItsOwnFactor) {
  const mpm::PlantModel nominal = mpm::config::load_plant(kWoodBerry);
  mpm::diagnosis::Result r;
  r.mismatch = true;
  auto gains = finding("gain", {{0, 0}, {1, 0}}, {{"gain_factor_y1", 1.3}, {"gain_factor_y2", 0.8}});
  gains.fitted = channel(nominal, 0, 0).tf;
  r.findings.push_back(gains);
  const mpm::CorrectedPlant c = mpm::apply_findings(nominal, r);
  EXPECT_EQ(c.changes, 1u);
  EXPECT_TRUE(c.not_applied.empty());
  for (const auto& [j, factor] : {std::pair{std::size_t{0}, 1.3}, std::pair{std::size_t{1}, 0.8}}) {
    mpm::DiscreteTf expected = channel(nominal, j, 0).tf;
    for (double& b : expected.num) b *= factor;
    expect_tf_near(channel(c.plant, j, 0).tf, expected);
  }
  expect_tf_near(channel(c.plant, 0, 1).tf, channel(nominal, 0, 1).tf);  // the other input's untouched
}

// A fit flagged implausible (a channel whose sign the fit reversed) is held
// back: the file says so and the channel keeps its nominal model.
TEST(WritePlant, AnImplausibleFindingIsHeldBack) {
  const mpm::PlantModel nominal = mpm::config::load_plant(kWoodBerryContinuous);
  mpm::diagnosis::Result r;
  r.mismatch = true;
  auto reversed = finding("gain", {{1, 0}}, {{"gain_factor", -0.6}});
  reversed.fitted = channel(nominal, 1, 0).tf;
  for (double& b : reversed.fitted->num) b *= -0.6;
  reversed.implausible = "the fitted gain factor -0.6 reverses the channel's sign";
  r.findings.push_back(reversed);
  auto plain = finding("gain", {{0, 1}}, {{"gain_factor", 1.2}});
  plain.fitted = channel(nominal, 0, 1).tf;
  for (double& b : plain.fitted->num) b *= 1.2;
  r.findings.push_back(plain);

  const mpm::CorrectedPlant c = mpm::apply_findings(nominal, r);
  EXPECT_EQ(c.changes, 1u);
  ASSERT_EQ(c.written.size(), 2u);
  EXPECT_EQ(c.written[0], mpm::Written::kImplausible);
  EXPECT_EQ(c.written[1], mpm::Written::kApplied);
  const std::string yaml = mpm::plant_yaml(c, kWoodBerryContinuous, "run.csv");
  EXPECT_NE(yaml.find("NOT applied (implausible: judge it before using it): gain: planted gain"), std::string::npos)
      << yaml;
  const std::string path = tmp("corrected.yaml");
  mpm::write_text_file(path, yaml, {kWoodBerryContinuous});
  const mpm::PlantModel back = mpm::config::load_plant(path);
  expect_tf_near(channel(back, 1, 0).tf, channel(nominal, 1, 0).tf);  // held back: nominal
  mpm::DiscreteTf g12 = channel(nominal, 0, 1).tf;
  for (double& b : g12.num) b *= 1.2;
  expect_tf_near(channel(back, 0, 1).tf, g12);  // applied
}

TEST(WritePlant, RefusesToOverwriteAnInput) {
  const std::string plant = tmp("plant.yaml"), csv = tmp("run.csv");
  std::filesystem::copy_file(kWoodBerry, plant, std::filesystem::copy_options::overwrite_existing);
  const std::string before = read_file(plant);
  ASSERT_EQ(mpm::test::run_quietly(kMpm + " simulate --scenario wood-berry-nominal --samples 1500 --seed 3 --out " + csv), 0);
  const auto run = mpm::test::run_captured(
      kMpm + " diagnose --quiet --plant " + plant + " --data " + csv + " --write-plant " + plant, "mpm_wp_");
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.err.find("refusing to overwrite an input"), std::string::npos) << run.err;
  EXPECT_EQ(read_file(plant), before);
  const auto run2 = mpm::test::run_captured(
      kMpm + " diagnose --quiet --plant " + plant + " --data " + csv + " --write-plant " + csv, "mpm_wp2_");
  EXPECT_NE(run2.exit_code, 0);
}

// The mission in one test: a gain mismatch the MPC hides is found, written
// back, and gone when the same recording is diagnosed with the written file.
TEST(WritePlant, CorrectedPlantLeavesNoMismatchOnTheChannel) {
  const std::string csv = tmp("run.csv"), json = tmp("before.json"), fixed = tmp("corrected.yaml"),
                    json2 = tmp("after.json");
  ASSERT_EQ(mpm::test::run_quietly(kMpm + " simulate --scenario wood-berry-nominal --edit y2.u1.gain=1.5 --samples 3000 "
                                          "--seed 7 --out " + csv),
            0);
  ASSERT_EQ(mpm::test::run_quietly(kMpm + " diagnose --quiet --plant " + kWoodBerry + " --data " + csv + " --json " +
                                   json + " --write-plant " + fixed),
            0);
  const std::string before = read_file(json);
  ASSERT_NE(before.find("\"physics\": \"gain\""), std::string::npos) << before;
  const std::string yaml = read_file(fixed);
  EXPECT_NE(yaml.find("CHANGED by mpm diagnose"), std::string::npos) << yaml;
  const mpm::PlantModel corrected = mpm::config::load_plant(fixed);
  const double k = channel(corrected, 1, 0).tf.dc_gain() / channel(mpm::config::load_plant(kWoodBerry), 1, 0).tf.dc_gain();
  EXPECT_NEAR(k, 1.5, 0.1);

  ASSERT_EQ(mpm::test::run_quietly(kMpm + " diagnose --quiet --plant " + fixed + " --data " + csv + " --json " + json2), 0);
  const std::string after = read_file(json2);
  EXPECT_EQ(after.find("{\"output\": \"y2\", \"input\": \"u1\"}"), std::string::npos) << after;
  EXPECT_NE(after.find("\"mismatch\": false"), std::string::npos) << after;
}

}  // namespace
