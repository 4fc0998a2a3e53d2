// Plant files that must load: the shared example data, the example plants in
// config/, and the optional parts of the format.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "config/plant_loader.hpp"

namespace mpm::config {
namespace {

namespace fs = std::filesystem;

const fs::path kDataDir = fs::path(MPM_SOURCE_DIR) / ".." / "shared" / "data";
const fs::path kConfigDir = fs::path(MPM_SOURCE_DIR) / "config";

std::vector<fs::path> case_folders() {
  std::vector<fs::path> out;
  for (const auto& entry : fs::directory_iterator(kDataDir))
    if (entry.is_directory()) out.push_back(entry.path());
  std::sort(out.begin(), out.end());
  return out;
}

TEST(SharedData, EveryPlantLoadsAndBindsItsRecording) {
  ASSERT_TRUE(fs::is_directory(kDataDir)) << "example data folder missing: " << kDataDir;
  const auto folders = case_folders();
  ASSERT_FALSE(folders.empty()) << "no case folders in " << kDataDir;
  for (const auto& folder : folders) {
    SCOPED_TRACE(folder.string());
    const fs::path plant_path = folder / "plant.yaml";
    const fs::path run_path = folder / "run.csv";
    ASSERT_TRUE(fs::exists(plant_path)) << "missing " << plant_path;
    ASSERT_TRUE(fs::exists(run_path)) << "missing " << run_path;
    PlantModel plant;
    Recording rec;
    BoundRecording bound;
    ASSERT_NO_THROW(plant = load_plant(plant_path.string()));
    ASSERT_NO_THROW(rec = load_recording(run_path.string()));
    ASSERT_NO_THROW(bound = bind(plant, rec));
    EXPECT_FALSE(plant.channels.empty());
    EXPECT_EQ(plant.noise.size(), plant.n_outputs());
    EXPECT_GT(rec.samples(), 100u);
    ASSERT_EQ(bound.inputs.size(), plant.n_inputs());
    ASSERT_EQ(bound.outputs.size(), plant.n_outputs());
    for (std::size_t i = 0; i < plant.n_inputs(); ++i)
      EXPECT_EQ(rec.names[bound.inputs[i]], plant.inputs[i]);
    for (std::size_t i = 0; i < plant.n_outputs(); ++i)
      EXPECT_EQ(rec.names[bound.outputs[i]], plant.outputs[i]);
    // Every channel is usable: normalised den, finite coefficients.
    for (const auto& ch : plant.channels) {
      EXPECT_DOUBLE_EQ(ch.tf.den.front(), 1.0);
      for (double x : ch.tf.num) EXPECT_TRUE(std::isfinite(x));
      EXPECT_GE(ch.tf.delay, 0);
    }
  }
}

TEST(SharedData, ThreeByThreeKeepsAbsentAndExplicitZeroApart) {
  const PlantModel plant = load_plant((kDataDir / "tt_missing_y1u3" / "plant.yaml").string());
  ASSERT_EQ(plant.n_inputs(), 3u);
  EXPECT_EQ(plant.channel(0, 2), nullptr);         // y1 <- u3: absent
  const ChannelModel* zero = plant.channel(2, 0);  // y3 <- u1: num: [0]
  ASSERT_NE(zero, nullptr);
  EXPECT_TRUE(zero->explicit_zero);
  EXPECT_TRUE(zero->tf.is_zero());
  const ChannelModel* mixed = plant.channel(0, 0);  // continuous form
  ASSERT_NE(mixed, nullptr);
  EXPECT_FALSE(mixed->explicit_zero);
  ASSERT_TRUE(mixed->continuous.has_value());
  EXPECT_DOUBLE_EQ(mixed->continuous->dead_time, 2.0);
  EXPECT_FALSE(plant.channel(1, 0)->continuous.has_value());  // discrete form
}

TEST(ExamplePlants, WoodBerryDiscreteHasThePaperModel) {
  const PlantModel plant = load_plant((kConfigDir / "wood-berry.yaml").string());
  EXPECT_EQ(plant.name, "wood-berry");
  EXPECT_EQ(plant.sample_time, 1.0);
  ASSERT_EQ(plant.channels.size(), 4u);
  const ChannelModel* g21 = plant.channel(1, 0);
  ASSERT_NE(g21, nullptr);
  EXPECT_EQ(g21->tf.num, std::vector<double>{0.5786});
  EXPECT_EQ(g21->tf.den, (std::vector<double>{1.0, -0.9123}));
  EXPECT_EQ(g21->tf.delay, 8);
  ASSERT_TRUE(plant.noise[1].has_value());
  EXPECT_EQ(plant.noise[1]->tf.den, (std::vector<double>{1.0, -0.9}));
  EXPECT_EQ(plant.noise[1]->variance, 1.0);
  ASSERT_TRUE(plant.operating_point.has_value());
  EXPECT_EQ(plant.operating_point->inputs, (std::vector<double>{15.0, 12.0}));
  EXPECT_EQ(plant.operating_point->outputs, (std::vector<double>{90.0, 5.0}));
}

// Leading zero coefficients of num are pure delay: compare in a form where
// they have been moved into `delay`, whichever way discretisation writes them.
DiscreteTf canonical(DiscreteTf tf) {
  while (tf.num.size() > 1 && tf.num.front() == 0.0) {
    tf.num.erase(tf.num.begin());
    ++tf.delay;
  }
  return tf;
}

TEST(ExamplePlants, WoodBerryContinuousAgreesWithDiscrete) {
  const PlantModel discrete = load_plant((kConfigDir / "wood-berry.yaml").string());
  const PlantModel continuous = load_plant((kConfigDir / "wood-berry-continuous.yaml").string());
  ASSERT_EQ(continuous.channels.size(), discrete.channels.size());
  for (const auto& c : continuous.channels) {
    SCOPED_TRACE(continuous.outputs[c.output] + " <- " + continuous.inputs[c.input]);
    ASSERT_TRUE(c.continuous.has_value());
    const ChannelModel* d = discrete.channel(c.output, c.input);
    ASSERT_NE(d, nullptr);
    const DiscreteTf a = canonical(c.tf);
    const DiscreteTf b = canonical(d->tf);
    EXPECT_EQ(a.delay, b.delay);
    ASSERT_EQ(a.num.size(), b.num.size());
    ASSERT_EQ(a.den.size(), b.den.size());
    for (std::size_t i = 0; i < a.num.size(); ++i) EXPECT_NEAR(a.num[i], b.num[i], 1e-3);
    for (std::size_t i = 0; i < a.den.size(); ++i) EXPECT_NEAR(a.den[i], b.den[i], 1e-3);
  }
  for (std::size_t o = 0; o < discrete.n_outputs(); ++o) {
    ASSERT_TRUE(continuous.noise[o] && discrete.noise[o]);
    EXPECT_EQ(continuous.noise[o]->tf.den, discrete.noise[o]->tf.den);
  }
}

TEST(PlantFormat, OptionalPartsTakeTheirDefaults) {
  const std::string yaml = R"(plant: minimal
sample_time: 0.5
inputs: [a, b]
outputs: [y]
x-note: extension keys are allowed
model:
  - output: y
    input: a
    num: [2, 1]
    x-origin: step test
  - output: y
    input: b
    num: [0]
)";
  const PlantModel plant = parse_plant(yaml, "minimal.yaml");
  EXPECT_EQ(plant.name, "minimal");
  EXPECT_EQ(plant.sample_time, 0.5);
  ASSERT_EQ(plant.channels.size(), 2u);
  const ChannelModel& first = plant.channels[0];
  EXPECT_EQ(first.tf.num, (std::vector<double>{2.0, 1.0}));
  EXPECT_EQ(first.tf.den, std::vector<double>{1.0});
  EXPECT_EQ(first.tf.delay, 0);
  EXPECT_FALSE(first.explicit_zero);
  EXPECT_TRUE(plant.channels[1].explicit_zero);
  ASSERT_EQ(plant.noise.size(), 1u);
  EXPECT_FALSE(plant.noise[0].has_value());
  EXPECT_FALSE(plant.operating_point.has_value());
}

TEST(PlantFormat, DenominatorIsNormalisedAndNoiseVarianceOptional) {
  const std::string yaml = R"(plant: scaled
sample_time: 2
inputs: [u]
outputs: [y1, y2]
model:
  - {output: y2, input: u, num: [1, 0.5], den: [2, -1], delay: 3}
noise:
  - output: y2
    num: [2, 1]
    den: [4, -2]
)";
  const PlantModel plant = parse_plant(yaml, "scaled.yaml");
  const ChannelModel* ch = plant.channel(1, 0);
  ASSERT_NE(ch, nullptr);
  EXPECT_EQ(ch->tf.num, (std::vector<double>{0.5, 0.25}));
  EXPECT_EQ(ch->tf.den, (std::vector<double>{1.0, -0.5}));
  EXPECT_EQ(ch->tf.delay, 3);
  EXPECT_FALSE(plant.noise[0].has_value());
  ASSERT_TRUE(plant.noise[1].has_value());
  EXPECT_EQ(plant.noise[1]->tf.num, (std::vector<double>{0.5, 0.25}));
  EXPECT_FALSE(plant.noise[1]->variance.has_value());
}

TEST(PlantFormat, ContinuousChannelIsDiscretisedAtTheSampleTime) {
  // 2/(10 s + 1), no dead time, at ts = 1: pole e^-0.1, gain 2 (1 - e^-0.1),
  // one sample of ZOH lag.
  const std::string yaml = R"(plant: lag
sample_time: 1
inputs: [u]
outputs: [y]
model:
  - output: y
    input: u
    continuous: {num: [2], den: [10, 1]}
)";
  const PlantModel plant = parse_plant(yaml, "lag.yaml");
  const DiscreteTf tf = canonical(plant.channels.at(0).tf);
  const double pole = std::exp(-0.1);
  ASSERT_EQ(tf.den.size(), 2u);
  EXPECT_NEAR(tf.den[1], -pole, 1e-12);
  ASSERT_EQ(tf.num.size(), 1u);
  EXPECT_NEAR(tf.num[0], 2.0 * (1.0 - pole), 1e-12);
  EXPECT_EQ(tf.delay, 1);
  EXPECT_EQ(plant.channels[0].continuous->dead_time, 0.0);
}

}  // namespace
}  // namespace mpm::config
