// The closed loop: deterministic per seed, streaming = batch, the recording
// layout of formats.md in absolute units, and the paper's unstable G32 case.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>
#include <vector>

#include "sim/closed_loop.hpp"
#include "sim/scenarios.hpp"
#include "sim/sim_test_support.hpp"

namespace mpm::sim {
namespace {

const Scenario& scenario(const char* name) {
  const Scenario* s = find_scenario(name);
  if (s == nullptr) throw std::runtime_error(std::string("no scenario ") + name);
  return *s;
}

config::Recording record(const char* name, std::uint64_t seed, std::size_t n, double noise_scale = 1.0) {
  const Scenario& s = scenario(name);
  LoopConfig c = s.loop;
  c.noise_scale = noise_scale;
  ClosedLoop loop(default_plant(s).model, c, seed);
  return simulate(loop, n);
}

// Root-mean-square of y_j - r_j over rows [from, to).
double rms_error(const config::Recording& rec, const std::string& y, std::size_t from, std::size_t to) {
  const auto cy = static_cast<Eigen::Index>(*rec.find(y)), cr = static_cast<Eigen::Index>(*rec.find("r_" + y));
  double s = 0.0;
  for (std::size_t k = from; k < to; ++k) {
    const double e = rec.data(static_cast<Eigen::Index>(k), cy) - rec.data(static_cast<Eigen::Index>(k), cr);
    s += e * e;
  }
  return std::sqrt(s / static_cast<double>(to - from));
}

TEST(ClosedLoop, SameSeedSameRecordingDifferentSeedDifferent) {
  const auto a = record("wood-berry-g21-gain", 7, 600);
  const auto b = record("wood-berry-g21-gain", 7, 600);
  const auto c = record("wood-berry-g21-gain", 8, 600);
  EXPECT_EQ(a.names, b.names);
  EXPECT_TRUE(a.data == b.data);
  EXPECT_FALSE(a.data == c.data);
}

TEST(ClosedLoop, StreamingStepsEqualTheBatchRecording) {
  const Scenario& s = scenario("quad-tank-nominal");
  const PlantModel m = default_plant(s).model;
  ClosedLoop batch(m, s.loop, 3), stream(m, s.loop, 3);
  const auto rec = simulate(batch, 300);
  std::vector<double> row(stream.column_names().size());
  for (Eigen::Index k = 0; k < 300; ++k) {
    const LoopSample& smp = stream.step();
    EXPECT_EQ(smp.k, k);
    stream.fill_row(smp, row.data());
    for (Eigen::Index c = 0; c < rec.data.cols(); ++c) ASSERT_EQ(row[static_cast<std::size_t>(c)], rec.data(k, c));
  }
}

TEST(ClosedLoop, RecordingHasTheFormatsColumnsAndBindsToItsPlant) {
  const Scenario& s = scenario("wood-berry-feed-flow");
  const PlantModel m = default_plant(s).model;
  ClosedLoop loop(m, s.loop, 1);
  const auto rec = simulate(loop, 200);
  EXPECT_EQ(rec.names, (std::vector<std::string>{"t", "u1", "u2", "y1", "y2", "r_y1", "r_y2", "feed_flow"}));
  for (Eigen::Index k = 0; k < 200; ++k) EXPECT_EQ(rec.data(k, 0), static_cast<double>(k) * m.sample_time);
  const std::string path = std::string(MPM_BINARY_DIR) + "/sim_test_feed_flow.csv";
  config::write_recording(path, rec);
  const auto back = config::load_recording(path);
  const auto bound = config::bind(m, back);
  ASSERT_EQ(bound.extra.size(), 1u);
  EXPECT_EQ(back.names[bound.extra[0]], "feed_flow");
  EXPECT_NEAR(back.data.col(7).mean(), 2.45, 0.3);  // around its operating value
  EXPECT_TRUE(back.data.isApprox(rec.data, 1e-15));
  std::remove(path.c_str());
}

// The reference model's outputs, recorded beside the loop's: (recording, reference).
std::pair<config::Recording, config::Recording> record_with_reference(const char* name, const PlantModel& reference,
                                                                      std::size_t n, long warmup) {
  const Scenario& s = scenario(name);
  LoopConfig c = s.loop;
  c.warmup = warmup;
  ClosedLoop loop(default_plant(s).model, c, 5, &reference);
  config::Recording ref;
  auto rec = simulate(loop, n, "run", &ref);
  return {std::move(rec), std::move(ref)};
}

TEST(ClosedLoop, AReferenceThatIsThePlantReadsWhatItsSensorsRead) {
  const Scenario& s = scenario("wood-berry-nominal");
  const auto [rec, ref] = record_with_reference("wood-berry-nominal", default_plant(s).model, 800, s.loop.warmup);
  EXPECT_EQ(ref.names, (std::vector<std::string>{"t", "y1", "y2"}));
  EXPECT_TRUE(ref.data.col(0) == rec.data.col(0));
  // The same innovations through the same filters, the same inputs through the same channels.
  EXPECT_TRUE(ref.data.col(1) == rec.data.col(3));
  EXPECT_TRUE(ref.data.col(2) == rec.data.col(4));
  EXPECT_GT((rec.data.col(4).array() - rec.data.col(4).mean()).abs().maxCoeff(), 0.5);  // the loop moved
}

TEST(ClosedLoop, TheOutputsMinusTheReferenceAreWhatTheReferenceLeavesOut) {
  // The plant is the full Wood-Berry model; the reference lacks y2 <- u1. The
  // difference is then exactly that channel's response to the recorded u1
  // (no warm-up, so that it starts from rest with the recording), and y1's is 0.
  const Scenario& s = scenario("wood-berry-nominal");
  const PlantModel full = default_plant(s).model;
  PlantModel lacking = full, only = full;
  std::erase_if(lacking.channels, [](const ChannelModel& c) { return c.output == 1 && c.input == 0; });
  std::erase_if(only.channels, [](const ChannelModel& c) { return !(c.output == 1 && c.input == 0); });
  ASSERT_EQ(lacking.channels.size() + 1, full.channels.size());
  ASSERT_EQ(only.channels.size(), 1u);
  const auto [rec, ref] = record_with_reference("wood-berry-nominal", lacking, 1500, 0);
  Plant channel = testing::build(only);
  const std::vector<double> no_disturbance(2, 0.0);
  std::vector<double> y(2), u(2);
  double largest = 0.0;
  for (Eigen::Index k = 0; k < rec.data.rows(); ++k) {
    channel.measure(no_disturbance.data(), y.data());
    EXPECT_EQ(rec.data(k, 3), ref.data(k, 1)) << k;
    EXPECT_NEAR(rec.data(k, 4) - ref.data(k, 2), y[1], 1e-9) << k;
    largest = std::max(largest, std::abs(y[1]));
    for (std::size_t l = 0; l < 2; ++l)
      u[l] = rec.data(k, static_cast<Eigen::Index>(1 + l)) - full.operating_point->inputs[l];
    channel.apply(u.data(), nullptr);
  }
  EXPECT_GT(largest, 0.5);  // the channel carried something
}

TEST(ClosedLoop, AReferenceWithOtherSignalsIsRefused) {
  const Scenario& s = scenario("wood-berry-nominal");
  PlantModel other = default_plant(s).model;
  other.outputs[1] = "xD";
  EXPECT_THROW(ClosedLoop(default_plant(s).model, s.loop, 1, &other), std::invalid_argument);
  ClosedLoop without(default_plant(s).model, s.loop, 1);
  config::Recording ref;
  EXPECT_THROW(simulate(without, 10, "run", &ref), std::invalid_argument);
}

TEST(ClosedLoop, AnUnrecordedExtraInputActsButLeavesNoColumn) {
  const auto unmeasured = record("wood-berry-unmeasured-feed", 2, 500);
  const auto nominal = record("wood-berry-nominal", 2, 500);
  EXPECT_EQ(unmeasured.names, nominal.names);
  EXPECT_GT((unmeasured.data.col(4) - nominal.data.col(4)).cwiseAbs().maxCoeff(), 0.1);  // y2 moved
}

TEST(ClosedLoop, AbsoluteUnitsAndTable8SetpointsOnTheFourByFour) {
  const auto rec = record("quad-tank-4x4-nominal", 1, 1500, /*noise_scale=*/0.0);
  const auto r1 = *rec.find("r_y1"), r4 = *rec.find("r_y4"), y1 = *rec.find("y1"), y2 = *rec.find("y2");
  for (Eigen::Index k = 0; k < 1500; ++k) {
    EXPECT_EQ(rec.data(k, static_cast<Eigen::Index>(r1)), k < 200 ? 8.0 : 23.0);
    EXPECT_LE(std::abs(rec.data(k, static_cast<Eigen::Index>(r4))), 9.0);
  }
  EXPECT_EQ(rec.data(0, static_cast<Eigen::Index>(y2)), 25.0);  // at rest at the operating point
  // Noiseless, matched: y1 reaches its new setpoint (the r4 sine stirs it a little).
  double mean_y1 = 0.0;
  for (Eigen::Index k = 1000; k < 1500; ++k) mean_y1 += rec.data(k, static_cast<Eigen::Index>(y1)) / 500.0;
  EXPECT_NEAR(mean_y1, 23.0, 0.5);
}

TEST(ClosedLoop, NoiselessMatchedWoodBerryTracksItsSetpoints) {
  const auto rec = record("wood-berry-nominal", 4, 3000, 0.0);
  // Setpoints change every 300-600 samples; 250 samples after any change
  // the outputs are on target.
  Eigen::Index last_change = 0;
  int checked = 0;
  for (Eigen::Index k = 1; k < 3000; ++k) {
    if (rec.data(k, 5) != rec.data(k - 1, 5) || rec.data(k, 6) != rec.data(k - 1, 6)) last_change = k;
    if (k - last_change > 250) {
      ++checked;
      EXPECT_NEAR(rec.data(k, 3), rec.data(k, 5), 1e-3) << k;
      EXPECT_NEAR(rec.data(k, 4), rec.data(k, 6), 1e-3) << k;
    }
  }
  EXPECT_GT(checked, 300);
}

TEST(ClosedLoop, G32IntegratorLoopDivergesWhileNominalStaysBounded) {
  const auto bad = record("quad-tank-g32-integrator", 1, 600);
  const auto good = record("quad-tank-4x4-nominal", 1, 600);
  double previous = 0.0;
  for (std::size_t w = 0; w < 6; ++w) {
    const double e = rms_error(bad, "y3", w * 100, (w + 1) * 100);
    EXPECT_GT(e, previous) << "window " << w;  // the error keeps growing
    previous = e;
  }
  EXPECT_GT(previous, 100.0 * rms_error(good, "y3", 500, 600));
  for (const char* y : {"y1", "y2", "y3", "y4"}) {
    const double early = rms_error(good, y, 300, 450), late = rms_error(good, y, 450, 600);
    EXPECT_LT(late, 2.0 * early) << y;
    EXPECT_LT(late, 10.0) << y;
  }
}

TEST(ClosedLoop, InputLimitsAreHonouredInTheRecording) {
  const Scenario& s = scenario("quad-tank-g32-integrator");  // pushes every input to its limits
  const auto rec = record("quad-tank-g32-integrator", 1, 1000);
  for (std::size_t l = 0; l < 4; ++l) {
    const auto c = static_cast<Eigen::Index>(1 + l);
    EXPECT_GE(rec.data.col(c).minCoeff(), s.loop.mpc.input_lower[l] - 1e-9);
    EXPECT_LE(rec.data.col(c).maxCoeff(), s.loop.mpc.input_upper[l] + 1e-9);
    EXPECT_NEAR(std::max(-rec.data.col(c).minCoeff(), rec.data.col(c).maxCoeff()), 10.0, 1e-9);
  }
}

TEST(ClosedLoop, RejectsConfigurationsThatDoNotFitThePlant) {
  const Scenario& s = scenario("wood-berry-g21-gain");
  const PlantModel quad = testing::example_plant("quad-tank.yaml");
  EXPECT_THROW(ClosedLoop(quad, s.loop, 1), std::invalid_argument);  // names y2/u1 unknown there
  LoopConfig c = scenario("wood-berry-nominal").loop;
  c.setpoints.pop_back();
  EXPECT_THROW(ClosedLoop(testing::example_plant("wood-berry.yaml"), c, 1), std::invalid_argument);
}

}  // namespace
}  // namespace mpm::sim
