// `mpm simulate --scenario plant-nominal --plant FILE` end to end: it needs
// --plant (usage error otherwise), runs on the 2x2, 3x3 and 4x4 example
// plants with their columns, equals the loop tuned in-process, and takes
// --edit like every scenario.
#include <sys/wait.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "config/plant_loader.hpp"
#include "sim/closed_loop.hpp"
#include "sim/scenarios.hpp"
#include "support/cli.hpp"

namespace {

using mpm::test::kMpm;
using mpm::test::read_file;

const std::string kConfig = std::string(MPM_SOURCE_DIR) + "/config/";

using mpm::test::CliRun;

std::string tmp_path(const std::string& name) { return mpm::test::per_test_tmp_path("mpm_simplant_", name); }

// Runs `mpm simulate ARGS`, capturing its exit code, stdout and stderr.
CliRun simulate(const std::string& args) { return mpm::test::run_captured(kMpm + " simulate " + args, "mpm_simplant_"); }

// plant-nominal's recording on config/<plant> (seed 3, 400 samples) plus `edits`.
std::string recording(const std::string& name, const std::string& plant, const std::string& edits = "",
                      std::string* wrote = nullptr) {
  const std::string csv = tmp_path(name + ".csv");
  std::remove(csv.c_str());
  const CliRun r = simulate("--scenario plant-nominal --plant " + kConfig + plant + " --samples 400 --seed 3 " + edits +
                            " --out " + csv);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  if (wrote) *wrote = r.out;
  return read_file(csv);
}

std::string header(const std::string& csv) { return csv.substr(0, csv.find('\n')); }

TEST(SimulatePlantCli, WithoutPlantIsAUsageError) {
  const std::string csv = tmp_path("refused.csv");
  std::remove(csv.c_str());
  const CliRun r = simulate("--scenario plant-nominal --out " + csv);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("plant-nominal needs --plant FILE"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("usage: mpm simulate"), std::string::npos) << r.err;
  EXPECT_TRUE(read_file(csv).empty());  // nothing written, no default plant tried
}

// simulate-live builds the same loop, so it refuses the same way (before
// it opens any transport).
TEST(SimulatePlantCli, SimulateLiveWithoutPlantIsAUsageError) {
  const CliRun r =
      mpm::test::run_captured(kMpm + " simulate-live --scenario plant-nominal --publish lcm --samples 5", "mpm_simplant_");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("plant-nominal needs --plant FILE"), std::string::npos) << r.err;
  EXPECT_EQ(r.out.find("published"), std::string::npos) << r.out;
}

TEST(SimulatePlantCli, RunsOnEveryExamplePlantWithItsColumns) {
  for (const auto& [plant, columns] : std::initializer_list<std::pair<const char*, const char*>>{
           {"wood-berry.yaml", "t,u1,u2,y1,y2,r_y1,r_y2"},
           {"three-by-three.yaml", "t,u1,u2,u3,y1,y2,y3,r_y1,r_y2,r_y3"},
           {"quad-tank-4x4.yaml", "t,u1,u2,u3,u4,y1,y2,y3,y4,r_y1,r_y2,r_y3,r_y4"}}) {
    std::string wrote;
    const std::string csv = recording(std::string("run_") + plant, plant, "", &wrote);
    EXPECT_EQ(header(csv), columns) << plant;
    EXPECT_NE(wrote.find("400 samples of plant-nominal (plant " + kConfig + plant), std::string::npos) << wrote;
    EXPECT_NE(wrote.find("input limits active at 0 samples"), std::string::npos) << wrote;
  }
}

// The command runs the loop tuned from the file's model, nothing else.
TEST(SimulatePlantCli, EqualsTheLoopTunedInProcess) {
  const std::string cli = recording("cli", "three-by-three.yaml");
  const mpm::PlantModel model = mpm::config::load_plant(kConfig + "three-by-three.yaml");
  mpm::sim::ClosedLoop loop(model, mpm::sim::scenario_loop(*mpm::sim::find_scenario("plant-nominal"), model), 3);
  const std::string coded = tmp_path("coded.csv");
  mpm::config::write_recording(coded, mpm::sim::simulate(loop, 400));
  ASSERT_GT(cli.size(), 1000u);
  EXPECT_EQ(cli, read_file(coded));
  EXPECT_EQ(cli, recording("cli_again", "three-by-three.yaml"));  // same seed, same run
}

TEST(SimulatePlantCli, EditChangesTheRunAndIsReported) {
  const std::string nominal = recording("nominal", "three-by-three.yaml");
  std::string wrote;
  const std::string edited = recording("edited", "three-by-three.yaml", "--edit y2.u1.delay=2", &wrote);
  EXPECT_EQ(header(edited), header(nominal));
  EXPECT_NE(edited, nominal);
  EXPECT_NE(wrote.find("plant-nominal with --edit y2.u1.delay=2"), std::string::npos) << wrote;
  // A name the plant file does not have is refused as for any scenario.
  const CliRun bad = simulate("--scenario plant-nominal --plant " + kConfig +
                              "three-by-three.yaml --edit y4.u1.gain=2 --out " + tmp_path("bad.csv"));
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("unknown output 'y4' (outputs: y1, y2, y3)"), std::string::npos) << bad.err;
}

// Column `name` of a recording file, read by the project's CSV reader.
Eigen::VectorXd csv_column(const mpm::config::Recording& rec, const std::string& name) {
  const auto c = rec.find(name);
  EXPECT_TRUE(c.has_value()) << name;
  return c ? Eigen::VectorXd(rec.data.col(static_cast<Eigen::Index>(*c))) : Eigen::VectorXd();
}

// --reference-out: what the reference model would have measured on the run.
// The unedited model reads exactly the recording's outputs; an edit of y1 <- u1
// shows on y1 alone.
TEST(SimulatePlantCli, ReferenceOutIsWhatTheModelWouldHaveMeasured) {
  const std::string plant = kConfig + "three-by-three.yaml";
  for (const std::string edit : {"", "--edit y1.u1.gain=1.5"}) {
    const std::string csv = tmp_path("ref_run.csv"), ref = tmp_path("ref_model.csv");
    std::remove(csv.c_str());
    std::remove(ref.c_str());
    const CliRun r = simulate("--scenario plant-nominal --plant " + plant + " --samples 300 --seed 4 " + edit +
                              " --out " + csv + " --reference-out " + ref);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("wrote " + ref + ": what the reference model " + plant), std::string::npos) << r.out;
    EXPECT_EQ(header(read_file(ref)), "t,y1,y2,y3");
    const auto run = mpm::config::load_recording(csv), model = mpm::config::load_recording(ref);
    EXPECT_TRUE(csv_column(model, "t") == csv_column(run, "t"));
    EXPECT_TRUE(csv_column(model, "y2") == csv_column(run, "y2")) << edit;
    EXPECT_TRUE(csv_column(model, "y3") == csv_column(run, "y3")) << edit;
    EXPECT_EQ(csv_column(model, "y1") == csv_column(run, "y1"), edit.empty()) << edit;
    EXPECT_EQ(csv_column(model, "y1").size(), 300);
  }
}

TEST(SimulatePlantCli, ReferenceFlagsRefuseWhatCannotWork) {
  const std::string base = "--scenario plant-nominal --plant " + kConfig + "three-by-three.yaml --samples 20 ";
  const std::string csv = tmp_path("refused_run.csv"), ref = tmp_path("refused_ref.csv");
  std::remove(ref.c_str());
  for (const auto& [args, says] : std::initializer_list<std::pair<std::string, std::string>>{
           {"--reference-plant " + kConfig + "three-by-three.yaml --out " + csv, "--reference-plant needs --reference-out"},
           {"--out " + csv + " --reference-out " + csv, "--reference-out: the same file as --out"},
           {"--out " + csv + " --reference-out " + ref + " --reference-plant " + kConfig + "wood-berry.yaml",
            "its inputs and outputs differ"}}) {
    const CliRun r = simulate(base + args);
    EXPECT_EQ(r.exit_code, 2) << args << ": " << r.err;
    EXPECT_NE(r.err.find(says), std::string::npos) << args << ": " << r.err;
    EXPECT_TRUE(read_file(ref).empty()) << args;
  }
  // An input file is never overwritten.
  const std::string before = read_file(kConfig + "three-by-three.yaml");
  const CliRun r = simulate(base + "--out " + csv + " --reference-out " + kConfig + "three-by-three.yaml");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("refusing to overwrite an input"), std::string::npos) << r.err;
  EXPECT_EQ(read_file(kConfig + "three-by-three.yaml"), before);
}

// Mean |u(k) - u(k-1)| of the first input column (column 1 after t).
double mean_input_move(const std::string& csv) {
  std::size_t at = csv.find('\n') + 1;
  double previous = 0.0, sum = 0.0;
  int rows = 0;
  while (at < csv.size()) {
    const std::size_t comma = csv.find(',', at);
    const double u = std::strtod(csv.c_str() + comma + 1, nullptr);
    if (rows > 0) sum += std::abs(u - previous);
    previous = u;
    ++rows;
    at = csv.find('\n', at);
    if (at == std::string::npos) break;
    ++at;
  }
  return rows > 1 ? sum / (rows - 1) : 0.0;
}

// A tighter controller answers the noise with more input movement: the
// excitation a mismatch is detected by.
TEST(SimulatePlantCli, MoveWeightScaleSetsHowBusyTheInputsAre) {
  const std::string calm = recording("calm", "three-by-three.yaml");
  std::string wrote;
  const std::string tight = recording("tight", "three-by-three.yaml", "--move-weight-scale 0.001", &wrote);
  EXPECT_GT(mean_input_move(tight), 3.0 * mean_input_move(calm));
  EXPECT_NE(wrote.find("(move weights x 0.001)"), std::string::npos) << wrote;
  for (const char* bad : {"0", "-1", "nan", "abc"}) {
    const CliRun r = simulate("--scenario plant-nominal --plant " + kConfig + "three-by-three.yaml --move-weight-scale " +
                              bad + " --out " + tmp_path("bad.csv"));
    EXPECT_EQ(r.exit_code, 2) << bad << ": " << r.err;
    EXPECT_NE(r.err.find("--move-weight-scale"), std::string::npos) << bad << ": " << r.err;
  }
}

TEST(SimulatePlantCli, ListAndHelpNameIt) {
  const CliRun list = simulate("--list");
  EXPECT_EQ(list.exit_code, 0);
  const auto line = list.out.find("plant-nominal");
  ASSERT_NE(line, std::string::npos) << list.out;
  EXPECT_NE(list.out.find("[--plant FILE]", line), std::string::npos) << list.out;
  const CliRun help = simulate("--help");
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_NE(help.out.find("required by plant-nominal"), std::string::npos) << help.out;
}

}  // namespace
