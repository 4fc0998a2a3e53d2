// `mpm simulate --edit SPEC` end to end: the built binary's recording equals
// the same loop run in-process with the edit written in code, edits combine
// with each other and with the scenario's, and bad specs are usage errors
// that name the spec.
#include <sys/wait.h>

#include <cstdlib>
#include <string>

#include <gtest/gtest.h>

#include "config/plant_loader.hpp"
#include "sim/closed_loop.hpp"
#include "sim/scenarios.hpp"
#include "support/cli.hpp"

namespace {

using mpm::test::kMpm;
using mpm::test::read_file;

using mpm::test::CliRun;

std::string tmp_path(const std::string& name) { return mpm::test::per_test_tmp_path("mpm_simedit_", name); }

// Runs `mpm simulate ARGS`, capturing its exit code, stdout and stderr.
CliRun simulate(const std::string& args) { return mpm::test::run_captured(kMpm + " simulate " + args, "mpm_simedit_"); }

// The recording CSV of `scenario` (seed 3, 400 samples) plus `edits`.
std::string recording(const std::string& name, const std::string& scenario, const std::string& edits = "") {
  const std::string csv = tmp_path(name + ".csv");
  std::remove(csv.c_str());
  const CliRun r = simulate("--scenario " + scenario + " --samples 400 --seed 3 " + edits + " --out " + csv);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return read_file(csv);
}

TEST(SimulateEditCli, GainEditEqualsTheChannelEditInCode) {
  const std::string cli = recording("cli_gain", "wood-berry-nominal", "--edit y2.u1.gain=1.5");

  const mpm::PlantModel model = mpm::config::load_plant(mpm::test::config_file("wood-berry.yaml"));
  mpm::sim::LoopConfig loop = mpm::sim::find_scenario("wood-berry-nominal")->loop;
  mpm::sim::ChannelEdit g21;
  g21.output = "y2";
  g21.input = "u1";
  g21.gain_factor = 1.5;
  loop.plant.channels = {g21};
  mpm::sim::ClosedLoop closed(model, loop, 3);
  const std::string coded_csv = tmp_path("coded_gain.csv");
  mpm::config::write_recording(coded_csv, mpm::sim::simulate(closed, 400));

  ASSERT_GT(cli.size(), 1000u);
  EXPECT_EQ(cli, read_file(coded_csv));
  EXPECT_NE(cli, recording("nominal", "wood-berry-nominal"));
}

// The README's example: the paper's G21 x 1.2 case from the command line.
TEST(SimulateEditCli, GainEditEqualsTheBuiltInScenario) {
  EXPECT_EQ(recording("cli_g21", "wood-berry-nominal", "--edit y2.u1.gain=1.2"),
            recording("builtin_g21", "wood-berry-g21-gain"));
}

// The paper's G21 x 1.5 + G12 pole x 0.9 case, built from the nominal
// scenario on the command line (and the `--edit=SPEC` form).
TEST(SimulateEditCli, RepeatedEditsBuildTheTwoChannelScenario) {
  EXPECT_EQ(recording("cli_two", "wood-berry-nominal", "--edit y2.u1.gain=1.5 --edit=y1.u2.pole=0.9"),
            recording("builtin_two", "wood-berry-g21-g12"));
}

// A key the scenario sets is replaced, not compounded: the G21 x 1.2
// scenario with --edit y2.u1.gain=1.5 is the nominal loop with G21 x 1.5.
TEST(SimulateEditCli, EditReplacesTheScenarioKey) {
  EXPECT_EQ(recording("replaced", "wood-berry-g21-gain", "--edit y2.u1.gain=1.5"),
            recording("nominal_15", "wood-berry-nominal", "--edit y2.u1.gain=1.5"));
  EXPECT_NE(recording("replaced_12", "wood-berry-g21-gain", "--edit y2.u1.gain=1.5"),
            recording("builtin_12", "wood-berry-g21-gain"));
}

TEST(SimulateEditCli, WroteLineNamesTheEdits) {
  const std::string csv = tmp_path("wrote.csv");
  const CliRun r = simulate("--scenario wood-berry-nominal --samples 50 --edit u2.actuator_lag=0.45 --edit "
                         "y1.sensor_lag=0.5 --out " + csv);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("wood-berry-nominal with --edit u2.actuator_lag=0.45, y1.sensor_lag=0.5"), std::string::npos)
      << r.out;
  const CliRun plain = simulate("--scenario wood-berry-nominal --samples 50 --out " + csv);
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_EQ(plain.out.find("--edit"), std::string::npos) << plain.out;
}

TEST(SimulateEditCli, BadSpecsAreUsageErrorsNamingTheSpec) {
  const std::string csv = tmp_path("refused.csv");
  for (const auto& [spec, why] : std::initializer_list<std::pair<const char*, const char*>>{
           {"y3.u1.gain=2", "unknown output 'y3'"},
           {"y2.u7.gain=2", "unknown input 'u7'"},
           {"y2.u1.gian=2", "unknown key 'gian'"},
           {"y2.u1.gain=two", "expected a number"},
           {"y2.u1.gain=nan", "finite"},
           {"y2.u1.lag=1.5", "must be in [0, 1)"},
           {"u1.lower=1", "must be <= 0"},
           {"gain=2", "expected OUTPUT.INPUT.KEY=VALUE"}}) {
    std::remove(csv.c_str());
    const CliRun r = simulate(std::string("--scenario wood-berry-nominal --samples 50 --edit ") + spec + " --out " + csv);
    EXPECT_EQ(r.exit_code, 2) << spec;
    EXPECT_NE(r.err.find(std::string("--edit '") + spec + "'"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(why), std::string::npos) << r.err;
    EXPECT_TRUE(read_file(csv).empty()) << spec;  // nothing written
  }
  const CliRun twice = simulate("--scenario wood-berry-nominal --edit u1.upper=1 --edit u1.upper=2 --out " + csv);
  EXPECT_EQ(twice.exit_code, 2);
  EXPECT_NE(twice.err.find("already given by 'u1.upper=1'"), std::string::npos) << twice.err;
  const CliRun tank = simulate("--scenario quad-tank-nominal --edit level1.pump1.gain=2 --out " + csv);
  EXPECT_EQ(tank.exit_code, 2);
  EXPECT_NE(tank.err.find("takes no channel edits"), std::string::npos) << tank.err;
}

TEST(SimulateEditCli, HelpDescribesEdit) {
  const CliRun r = simulate("--help");
  EXPECT_EQ(r.exit_code, 0);
  for (const char* word : {"--edit SPEC", "OUTPUT.INPUT.KEY=VALUE", "actuator_lag", "sensor_lag", "time_constant"})
    EXPECT_NE(r.out.find(word), std::string::npos) << word;
}

}  // namespace
