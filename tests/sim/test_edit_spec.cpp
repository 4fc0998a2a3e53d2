// `--edit SPEC` text -> plant edits: each key lands in its field, bad specs
// are refused with a message naming them, and a loop run with parsed edits is
// the loop run with the same edits written in code.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "sim/closed_loop.hpp"
#include "sim/edit_spec.hpp"
#include "sim/scenarios.hpp"
#include "sim/sim_test_support.hpp"
#include "support/mentions.hpp"

namespace mpm::sim {
namespace {

using test::mentions;

const std::vector<std::string> kInputs{"u1", "u2"}, kOutputs{"y1", "y2"};

EditSpec parse(const std::string& text) { return parse_edit(text, kInputs, kOutputs); }

PlantSpec applied(const std::vector<std::string>& texts, PlantSpec plant = {}) {
  std::vector<EditSpec> specs;
  for (const auto& t : texts) specs.push_back(parse(t));
  apply_edits(specs, plant);
  return plant;
}

// The message of the std::invalid_argument `f` throws ("" if none).
template <class F>
std::string error_of(F f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

std::string parse_error(const std::string& text) {
  return error_of([&] { parse(text); });
}

TEST(EditSpec, ChannelKeysSetTheirFields) {
  const PlantSpec p = applied({"y2.u1.gain=0.8", "y2.u1.pole=0.9", "y2.u1.time_constant=1.3", "y2.u1.delay=3",
                               "y2.u1.lag=0.6", "y2.u1.integrator"});
  ASSERT_EQ(p.channels.size(), 1u);  // one channel: combined into one edit
  const ChannelEdit& e = p.channels[0];
  EXPECT_EQ(e.output, "y2");
  EXPECT_EQ(e.input, "u1");
  EXPECT_EQ(e.gain_factor, 0.8);
  EXPECT_EQ(e.pole_factor, 0.9);
  EXPECT_EQ(e.time_constant_factor, 1.3);
  EXPECT_EQ(e.extra_delay, 3);
  EXPECT_EQ(e.extra_lag_pole, 0.6);
  EXPECT_TRUE(e.add_integrator);
  EXPECT_TRUE(p.inputs.empty());
  EXPECT_TRUE(p.outputs.empty());
}

TEST(EditSpec, EachChannelKeyLeavesTheOtherFieldsAlone) {
  const ChannelEdit nominal;
  const PlantSpec p = applied({"y1.u2.delay=2"});
  ASSERT_EQ(p.channels.size(), 1u);
  EXPECT_EQ(p.channels[0].extra_delay, 2);
  EXPECT_EQ(p.channels[0].gain_factor, nominal.gain_factor);
  EXPECT_EQ(p.channels[0].pole_factor, nominal.pole_factor);
  EXPECT_EQ(p.channels[0].extra_lag_pole, nominal.extra_lag_pole);
  EXPECT_FALSE(p.channels[0].add_integrator);
  EXPECT_FALSE(applied({"y1.u2.integrator=0"}).channels[0].add_integrator);
  EXPECT_TRUE(applied({"y1.u2.integrator=1"}).channels[0].add_integrator);
  EXPECT_EQ(applied({"y1.u2.soft_saturation=0.3"}).channels[0].soft_saturation, 0.3);
  EXPECT_EQ(p.channels[0].soft_saturation, nominal.soft_saturation);
}

TEST(EditSpec, InputAndOutputKeysSetTheirFields) {
  const PlantSpec p =
      applied({"u2.actuator_lag=0.45", "u2.lower=-0.5", "u2.upper=0.9", "u2.deadband=0.25", "y1.sensor_lag=0.5"});
  ASSERT_EQ(p.inputs.size(), 1u);
  EXPECT_EQ(p.inputs[0].input, "u2");
  EXPECT_EQ(p.inputs[0].actuator_lag_pole, 0.45);
  EXPECT_EQ(p.inputs[0].lower_limit, -0.5);
  EXPECT_EQ(p.inputs[0].upper_limit, 0.9);
  EXPECT_EQ(p.inputs[0].deadband_width, 0.25);
  ASSERT_EQ(p.outputs.size(), 1u);
  EXPECT_EQ(p.outputs[0].output, "y1");
  EXPECT_EQ(p.outputs[0].sensor_lag_pole, 0.5);
  EXPECT_TRUE(p.channels.empty());
  // Only the stop given moves.
  const PlantSpec upper_only = applied({"u1.upper=0.9"});
  EXPECT_EQ(upper_only.inputs[0].lower_limit, -std::numeric_limits<double>::infinity());
}

TEST(EditSpec, SeparateTargetsGetSeparateEdits) {
  const PlantSpec p = applied({"y1.u1.gain=2", "y2.u1.gain=3", "y1.u1.delay=1", "u1.deadband=0.1", "u2.deadband=0.2"});
  ASSERT_EQ(p.channels.size(), 2u);
  EXPECT_EQ(p.channels[0].output, "y1");
  EXPECT_EQ(p.channels[0].gain_factor, 2.0);
  EXPECT_EQ(p.channels[0].extra_delay, 1);
  EXPECT_EQ(p.channels[1].output, "y2");
  EXPECT_EQ(p.channels[1].gain_factor, 3.0);
  EXPECT_EQ(p.channels[1].extra_delay, 0);
  ASSERT_EQ(p.inputs.size(), 2u);
  EXPECT_EQ(p.inputs[1].deadband_width, 0.2);
}

TEST(EditSpec, EditsGoOnTopOfTheScenarioAndReplaceOnlyTheKeysGiven) {
  PlantSpec scenario;
  ChannelEdit g12;
  g12.output = "y1";
  g12.input = "u2";
  g12.pole_factor = 0.9;
  g12.gain_factor = 1.1;
  scenario.channels = {g12};
  scenario.inputs = {InputEdit{"u1", 0.3}};
  const PlantSpec p = applied({"y1.u2.gain=1.5", "y2.u1.gain=1.2", "u1.upper=0.9"}, scenario);
  ASSERT_EQ(p.channels.size(), 2u);
  EXPECT_EQ(p.channels[0].gain_factor, 1.5);  // replaced
  EXPECT_EQ(p.channels[0].pole_factor, 0.9);  // kept
  EXPECT_EQ(p.channels[1].output, "y2");
  EXPECT_EQ(p.channels[1].gain_factor, 1.2);
  ASSERT_EQ(p.inputs.size(), 1u);
  EXPECT_EQ(p.inputs[0].actuator_lag_pole, 0.3);
  EXPECT_EQ(p.inputs[0].upper_limit, 0.9);
}

TEST(EditSpec, NumbersAcceptedInTheUsualForms) {
  EXPECT_EQ(parse("y2.u1.gain=-0.5").value, -0.5);
  EXPECT_EQ(parse("y2.u1.gain=+2").value, 2.0);
  EXPECT_EQ(parse("y2.u1.gain=1e-1").value, 0.1);
  EXPECT_EQ(parse("y2.u1.delay=10000").value, 10000.0);
  EXPECT_EQ(parse("u1.lower=0").value, 0.0);
}

TEST(EditSpec, NamesWithDotsAreSplitOnTheNames) {
  const EditSpec s = parse_edit("tank.level.pump.a.gain=2", {"pump.a"}, {"tank.level"});
  EXPECT_EQ(s.output, "tank.level");
  EXPECT_EQ(s.input, "pump.a");
  EXPECT_EQ(s.field, EditField::gain);
}

TEST(EditSpec, UnknownNamesAreNamedWithTheSpec) {
  EXPECT_TRUE(mentions(parse_error("y3.u1.gain=2"), {"'y3.u1.gain=2'", "unknown output 'y3'", "y1, y2"}));
  EXPECT_TRUE(mentions(parse_error("y2.u9.gain=2"), {"unknown input 'u9'"}));
  EXPECT_TRUE(mentions(parse_error("u3.actuator_lag=0.5"), {"unknown input 'u3'"}));
  // An output where an input belongs, and an input where an output does.
  EXPECT_TRUE(mentions(parse_error("y1.actuator_lag=0.5"), {"unknown input 'y1'"}));
  EXPECT_TRUE(mentions(parse_error("u1.sensor_lag=0.5"), {"unknown output 'u1'"}));
  EXPECT_TRUE(mentions(parse_error("y1.gain=2"), {"OUTPUT.INPUT"}));  // a channel key needs both names
}

TEST(EditSpec, UnknownKeysAndMalformedSpecsAreRefused) {
  // The key named, and the keys there are listed.
  EXPECT_TRUE(mentions(parse_error("y2.u1.gian=2"), {"'y2.u1.gian=2'", "unknown key 'gian'", "time_constant"}));
  for (const char* bad : {"", "gain=2", ".gain=2", "y2u1gain", "=1"})
    EXPECT_NE(parse_error(bad).find("expected OUTPUT.INPUT.KEY=VALUE"), std::string::npos) << bad;
  EXPECT_NE(parse_error("y2.u1.gain").find("needs a value"), std::string::npos);
}

TEST(EditSpec, BadNumbersAreRefused) {
  for (const char* bad : {"y2.u1.gain=", "y2.u1.gain=abc", "y2.u1.gain=1.5x", "y2.u1.gain= 1", "y2.u1.gain=1,5",
                          "y2.u1.gain=--1"}) {
    const std::string m = parse_error(bad);
    EXPECT_NE(m.find("expected a number"), std::string::npos) << bad << ": " << m;
    EXPECT_NE(m.find(std::string("'") + bad + "'"), std::string::npos) << m;
  }
  for (const char* bad : {"y2.u1.gain=inf", "y2.u1.gain=nan", "y2.u1.gain=1e999", "u1.lower=-inf"})
    EXPECT_NE(parse_error(bad).find("must be a finite number"), std::string::npos) << bad;
}

TEST(EditSpec, OutOfRangeValuesAreRefused) {
  const std::vector<std::pair<const char*, const char*>> cases{
      {"y2.u1.pole=0", "must be > 0"},
      {"y2.u1.pole=-0.5", "must be > 0"},
      {"y2.u1.time_constant=0", "must be > 0"},
      {"y2.u1.delay=-1", "whole number of samples"},
      {"y2.u1.delay=1.5", "whole number of samples"},
      {"y2.u1.delay=10001", "whole number of samples"},
      {"y2.u1.lag=1", "must be in [0, 1)"},
      {"y2.u1.lag=-0.1", "must be in [0, 1)"},
      {"y2.u1.integrator=2", "must be 1"},
      {"y2.u1.soft_saturation=-0.1", "must be >= 0"},
      {"u1.actuator_lag=1", "must be in [0, 1)"},
      {"u1.lower=0.5", "must be <= 0"},
      {"u1.upper=-0.5", "must be >= 0"},
      {"u1.deadband=-0.1", "must be >= 0"},
      {"y1.sensor_lag=1.2", "must be in [0, 1)"},
  };
  for (const auto& [text, why] : cases) {
    const std::string m = parse_error(text);
    EXPECT_NE(m.find(why), std::string::npos) << text << ": " << m;
    EXPECT_EQ(m.find(std::string("'") + text + "'"), 0u) << m;
  }
}

TEST(EditSpec, ConflictsFoundWhenApplying) {
  EXPECT_TRUE(mentions(error_of([] { applied({"y2.u1.gain=2", "y2.u1.gain=3"}); }),
                       {"'y2.u1.gain=3'", "already given by 'y2.u1.gain=2'"}));
  EXPECT_TRUE(mentions(error_of([] { applied({"u1.lower=0", "u1.upper=0"}); }),
                       {"'u1.upper=0'", "lower_limit must be below upper_limit"}));
  PlantSpec tank;
  tank.kind = ProcessKind::quad_tank;
  EXPECT_TRUE(mentions(error_of([&] { applied({"y1.u1.gain=2"}, tank); }), {"quadruple tank takes no channel edits"}));
  EXPECT_EQ(applied({"y1.sensor_lag=0.3"}, tank).outputs.size(), 1u);  // its transmitters may be edited
}

TEST(EditSpec, DescribeListsTheSpecsAsGiven) {
  EXPECT_EQ(describe({parse("y2.u1.gain=1.5"), parse("u2.actuator_lag=0.45")}), "y2.u1.gain=1.5, u2.actuator_lag=0.45");
  EXPECT_EQ(describe({}), "");
}

// The loop run from `--edit y2.u1.gain=1.5` text is the loop run from the
// ChannelEdit written in code, sample for sample; and not the nominal run.
TEST(EditSpec, ParsedGainEditRunsLikeTheCodedOne) {
  const Scenario& nominal = *find_scenario("wood-berry-nominal");
  const PlantModel model = testing::example_plant("wood-berry.yaml");

  LoopConfig parsed = nominal.loop;
  apply_edits({parse_edit("y2.u1.gain=1.5", model.inputs, model.outputs)}, parsed.plant);
  LoopConfig coded = nominal.loop;
  ChannelEdit g21;
  g21.output = "y2";
  g21.input = "u1";
  g21.gain_factor = 1.5;
  coded.plant.channels = {g21};

  ClosedLoop a(model, parsed, 5), b(model, coded, 5), c(model, nominal.loop, 5);
  const auto ra = simulate(a, 600), rb = simulate(b, 600), rc = simulate(c, 600);
  EXPECT_EQ(ra.names, rb.names);
  EXPECT_TRUE(ra.data == rb.data);
  EXPECT_GT((ra.data - rc.data).cwiseAbs().maxCoeff(), 1e-3);
}

}  // namespace
}  // namespace mpm::sim
