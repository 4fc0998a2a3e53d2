// Small CLI promises: `--version` names the project version; `mpm paper
// --out DIR` creates DIR (and its parents) when it does not exist.
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "support/cli.hpp"

namespace {

TEST(Cli, VersionIsTheProjectVersion) {
  const auto run = mpm::test::run_captured(mpm::test::kMpm + " --version", "mpm_version_");
  EXPECT_EQ(run.exit_code, 0);
  EXPECT_EQ(run.out, std::string("mpm ") + MPM_VERSION + "\n");
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
