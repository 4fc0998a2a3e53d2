// Caps on what a file may ask for (limits.hpp), refusal of non-regular files,
// StrictModes of the daemon's files and the safety of outputs: each case is
// a defect once measured on main (a 2000 x 2000 plant took 23 GB, /dev/zero
// was read until bad_alloc, a 1-million-column header was a bad_alloc, an
// output equal to an input overwrote the recording).
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "config/daemon_config.hpp"
#include "config/limits.hpp"
#include "config/output_file.hpp"
#include "config/plant_loader.hpp"
#include "config/strict_modes.hpp"
#include "config_test_util.hpp"

namespace mpm::config {
namespace {

using testing_util::temp_dir;
using testing_util::write_text;

std::string error_of(auto&& load) { return testing_util::config_error(load); }

std::string names(const char* prefix, std::size_t n) {
  std::string out = "[";
  for (std::size_t i = 0; i < n; ++i) out += (i ? ", " : "") + std::string(prefix) + std::to_string(i);
  return out + "]";
}

std::string plant_with(const std::string& channel_lines) {
  return "plant: p\nsample_time: 1\ninputs: [u1]\noutputs: [y1]\nmodel:\n  - output: y1\n"
         "    input: u1\n" +
         channel_lines;
}

TEST(Limits, TooManyInputsIsLocatedBeforeTheModelIsRead) {
  const std::string yaml = "plant: p\nsample_time: 1\ninputs: " + names("u", 2000) +
                           "\noutputs: " + names("y", 2000) + "\nmodel: []\n";
  const std::string e = error_of([&] { parse_plant(yaml, "big.yaml"); });
  EXPECT_NE(e.find("big.yaml:3:"), std::string::npos) << e;
  EXPECT_NE(e.find("inputs: expected 1..100 inputs, got 2000"), std::string::npos) << e;
}

TEST(Limits, OutputsCapIsConfigurable) {
  const std::string yaml = "plant: p\nsample_time: 1\ninputs: [u]\noutputs: " + names("y", 3) +
                           "\nmodel: []\n";
  Limits limits;
  limits.max_outputs = 2;
  const std::string e = error_of([&] { parse_plant(yaml, "p.yaml", limits); });
  EXPECT_NE(e.find("p.yaml:4:"), std::string::npos) << e;
  EXPECT_NE(e.find("outputs: expected 1..2 outputs, got 3"), std::string::npos) << e;
  EXPECT_NO_THROW(parse_plant(yaml, "p.yaml"));
}

TEST(Limits, DelayBeyondTheCapNamesKeyAndRange) {
  const std::string e = error_of([&] {
    parse_plant(plant_with("    num: [1]\n    den: [1, -0.5]\n    delay: 1000000\n"), "d.yaml");
  });
  EXPECT_NE(e.find("d.yaml:10:12: model[0].delay: expected a delay in 0..1000 samples, got 1000000"),
            std::string::npos)
      << e;
  EXPECT_NO_THROW(parse_plant(plant_with("    num: [1]\n    den: [1, -0.5]\n    delay: 1000\n"), "d.yaml"));
}

TEST(Limits, ContinuousDeadTimeBeyondTheCap) {
  const std::string e = error_of([&] {
    parse_plant(plant_with("    continuous: {num: [1], den: [10, 1], dead_time: 5000}\n"), "c.yaml");
  });
  EXPECT_NE(e.find("c.yaml:8:"), std::string::npos) << e;
  EXPECT_NE(e.find("model[0].continuous.dead_time: expected a dead time of 0..1000 samples"),
            std::string::npos)
      << e;
}

TEST(Limits, PolynomialLengthIsCapped) {
  std::string den = "[1";
  for (int k = 0; k < 300; ++k) den += ", 0";
  den += "]";
  const std::string e =
      error_of([&] { parse_plant(plant_with("    num: [1]\n    den: " + den + "\n"), "l.yaml"); });
  EXPECT_NE(e.find("l.yaml:9:10: model[0].den: expected at most 200 coefficients, got 301"),
            std::string::npos)
      << e;
}

TEST(Limits, UnstableDenNamesFileLineAndKey) {
  const std::string e =
      error_of([&] { parse_plant(plant_with("    num: [0.5]\n    den: [1, -2.5]\n"), "u.yaml"); });
  EXPECT_NE(e.find("u.yaml:9:10: model[0].den: expected a stable or integrating model"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("magnitude 2.5"), std::string::npos) << e;
  // An integrator stays allowed.
  EXPECT_NO_THROW(parse_plant(plant_with("    num: [0.5]\n    den: [1, -1]\n    delay: 1\n"), "i.yaml"));
}

TEST(Limits, OverflowingNormalisationNamesTheKey) {
  const std::string e =
      error_of([&] { parse_plant(plant_with("    num: [1e300]\n    den: [1e-300]\n"), "o.yaml"); });
  EXPECT_NE(e.find("o.yaml:9:10: model[0].den: cannot normalise"), std::string::npos) << e;
}

TEST(Limits, MillionColumnHeaderIsALocatedError) {
  std::string csv;
  csv.reserve(8'000'000);
  csv += "t";
  for (int c = 1; c < 1'000'000; ++c) csv += ",c" + std::to_string(c);
  csv += "\n0";
  csv.append(999'999, ',');
  csv += "\n";
  const std::string e = error_of([&] { parse_recording(csv, "wide.csv"); });
  EXPECT_EQ(e, "wide.csv:1: header: expected 1..10000 columns, got 1000000 (the limit is "
               "Limits::max_csv_columns)");
}

TEST(Limits, DeviceAndDirectoryAreNotRead) {
  for (const char* path : {"/dev/zero", "/dev/null"}) {
    const std::string e = error_of([&] { load_plant(path); });
    EXPECT_NE(e.find(std::string(path) + ": not a regular file"), std::string::npos) << e;
    EXPECT_NE(error_of([&] { load_recording(path); }).find("not a regular file"), std::string::npos);
  }
  const auto dir = temp_dir("limits_dir");
  EXPECT_NE(error_of([&] { load_plant(dir.string()); }).find("not a regular file"), std::string::npos);
}

TEST(Limits, FileSizeIsCapped) {
  const auto path = temp_dir("limits_size") / "big.yaml";
  write_text(path, "plant: p\n" + std::string(2000, '#') + "\n");
  Limits limits;
  limits.max_yaml_bytes = 1000;
  const std::string e = error_of([&] { load_plant(path.string(), limits); });
  EXPECT_NE(e.find("big.yaml: file is larger than the limit of 1000 bytes"), std::string::npos) << e;
}

// --- StrictModes of the daemon's files ----------------------------------------

struct DaemonFiles {
  std::filesystem::path config, plant;
};

DaemonFiles daemon_files(const std::string& tag) {
  const auto dir = temp_dir(tag);
  DaemonFiles f{dir / "mpmd.yaml", dir / "plant.yaml"};
  write_text(f.plant, plant_with("    num: [0.5]\n    den: [1, -0.5]\n    delay: 1\n"));
  write_text(f.config, "controller_id: c\nplant: plant.yaml\n");
  ::chmod(f.plant.c_str(), 0644);
  ::chmod(f.config.c_str(), 0644);
  return f;
}

TEST(StrictModes, PrivateFilesAreAccepted) {
  const DaemonFiles f = daemon_files("strict_ok");
  EXPECT_NO_THROW(load_daemon_config(f.config.string()));
}

TEST(StrictModes, GroupOrWorldWritableConfigIsRefused) {
  for (const mode_t mode : {mode_t{0666}, mode_t{0620}, mode_t{0602}}) {
    const DaemonFiles f = daemon_files("strict_cfg");
    ::chmod(f.config.c_str(), mode);
    const std::string e = error_of([&] { load_daemon_config(f.config.string()); });
    char octal[8];
    std::snprintf(octal, sizeof octal, "%04o", static_cast<unsigned>(mode));
    EXPECT_NE(e.find(f.config.string() + ": config file has mode " + octal), std::string::npos) << e;
  }
}

TEST(StrictModes, WritablePlantIsRefused) {
  const DaemonFiles f = daemon_files("strict_plant");
  ::chmod(f.plant.c_str(), 0646);
  const std::string e = error_of([&] { load_daemon_config(f.config.string()); });
  EXPECT_NE(e.find("plant.yaml: plant file has mode 0646"), std::string::npos) << e;
}

TEST(StrictModes, FileOfAnotherUserIsRefused) {
  if (::geteuid() != 0) GTEST_SKIP() << "needs root to give a file to another user";
  const DaemonFiles f = daemon_files("strict_owner");
  ASSERT_EQ(::chown(f.plant.c_str(), 12345, 12345), 0);
  const std::string e = error_of([&] { load_daemon_config(f.config.string()); });
  EXPECT_NE(e.find("plant.yaml: plant file is owned by uid 12345"), std::string::npos) << e;
}

// Found by fuzz_daemon_config: a plant path longer than PATH_MAX made
// std::filesystem::exists throw filesystem_error, which no caller expects.
TEST(DaemonConfigFuzz, OverlongPlantPathIsALocatedError) {
  const std::string yaml = "controller_id: c\nplant: wood" + std::string(5000, 'O') + "\n";
  const std::string e = error_of([&] { parse_daemon_config(yaml, "mpmd.yaml", ""); });
  EXPECT_NE(e.find("mpmd.yaml:2:8: plant: no such plant file"), std::string::npos) << e;
  const std::string dds = "controller_id: c\nplant: /dev/null\ntransport: {dds: {config: " +
                          std::string(5000, 'x') + "}}\n";
  const std::string d = error_of([&] { parse_daemon_config(dds, "mpmd.yaml", ""); });
  EXPECT_NE(d.find("mpmd.yaml:3:"), std::string::npos) << d;
  EXPECT_NE(d.find("no such Cyclone DDS configuration file"), std::string::npos) << d;
}

// --- Outputs -------------------------------------------------------------------

TEST(OutputFile, AnInputIsNeverAnOutput) {
  const auto dir = temp_dir("output_same");
  write_text(dir / "run.csv", "t\n0\n");
  std::filesystem::create_symlink(dir / "run.csv", dir / "link.csv");
  for (const auto& out : {dir / "run.csv", dir / "link.csv", dir / "." / "run.csv"}) {
    const std::string e = error_of([&] { refuse_input_as_output(out.string(), {(dir / "run.csv").string()}); });
    EXPECT_NE(e.find("refusing to overwrite an input"), std::string::npos) << out << e;
  }
  EXPECT_NO_THROW(refuse_input_as_output((dir / "new.json").string(), {(dir / "run.csv").string()}));
}

TEST(OutputFile, WriteErrorIsAnError) {
  EXPECT_NE(error_of([&] { write_output_file("/dev/full", "{}\n"); }).find("/dev/full"), std::string::npos);
}

}  // namespace
}  // namespace mpm::config
