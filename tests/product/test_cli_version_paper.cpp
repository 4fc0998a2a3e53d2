// Small CLI promises: `--version` names the project version; `mpm paper
// --out DIR` creates DIR (and its parents) when it does not exist.
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "support/cli.hpp"

namespace {

TEST(Cli, VersionIsTheProjectVersion) {
  const auto run = mpm::test::run_captured(mpm::test::kMpm + " --version", "mpm_version_");
  EXPECT_EQ(run.exit_code, 0);
  EXPECT_EQ(run.out, std::string("mpm ") + MPM_VERSION + "\n");
}

// Every command (as `mpm --help` lists them) answers --version and --help
// with 0 and an unknown option with 2, the usage on stderr (daemon/args.hpp).
TEST(Cli, EveryCommandAnswersVersionHelpAndUsageErrors) {
  const auto list = mpm::test::run_captured(mpm::test::kMpm + " --help", "mpm_commands_");
  ASSERT_EQ(list.exit_code, 0);
  std::vector<std::string> commands;
  std::istringstream lines(list.out.substr(list.out.find("commands:")));
  std::string line;
  std::getline(lines, line);
  while (std::getline(lines, line)) {
    std::istringstream words(line);
    std::string name;
    if (words >> name) commands.push_back(name);
  }
  ASSERT_GE(commands.size(), 6u) << list.out;
  for (const std::string& c : commands) {
    if (c == "bench") continue;  // runs mpm-bench, built with the bench (same frame: bench/mpm_bench_main.cpp)
    const auto version = mpm::test::run_captured(mpm::test::kMpm + " " + c + " --version", "mpm_version_");
    EXPECT_EQ(version.exit_code, 0) << c;
    EXPECT_EQ(version.out, "mpm " + c + " " + MPM_VERSION + "\n") << c;
    const auto help = mpm::test::run_captured(mpm::test::kMpm + " " + c + " --help", "mpm_help_");
    EXPECT_EQ(help.exit_code, 0) << c;
    EXPECT_NE(help.out.find("usage: mpm " + c), std::string::npos) << c << ": " << help.out;
    const auto bad = mpm::test::run_captured(mpm::test::kMpm + " " + c + " --no-such-option 1", "mpm_bad_");
    EXPECT_EQ(bad.exit_code, 2) << c;
    EXPECT_NE(bad.err.find("usage: mpm " + c), std::string::npos) << c << ": " << bad.err;
  }
}

TEST(Cli, PaperCreatesItsOutputFolder) {
  const std::string dir = mpm::test::per_test_tmp_path("mpm_paper_", "new/sub");
  std::filesystem::remove_all(std::filesystem::path(dir).parent_path());
  const auto run = mpm::test::run_captured(
      mpm::test::kMpm + " paper --scenario wood-berry-g21-gain --samples 600 --out " + dir, "mpm_paper_");
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_TRUE(std::filesystem::is_regular_file(dir + "/wood-berry-g21-gain.csv")) << run.err;
}

}  // namespace
