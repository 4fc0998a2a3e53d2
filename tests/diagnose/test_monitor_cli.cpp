// `mpm monitor` end to end: the replay split over threads (each a part of
// the outputs) gives the report one thread gives, byte for byte.
#include <cstdlib>
#include <string>

#include <gtest/gtest.h>

#include "support/cli.hpp"

namespace {

const std::string kQuadTank = std::string(MPM_SOURCE_DIR) + "/config/quad-tank-4x4.yaml";

using mpm::test::kMpm;
using mpm::test::read_file;

std::string tmp_path(const std::string& name) { return mpm::test::tmp_path("mpm_monitor_", name); }
int run(const std::string& cmd) { return mpm::test::run_quietly(cmd); }

TEST(MonitorCli, ThreadsDoNotChangeTheReport) {
  const std::string csv = tmp_path("g23.csv");
  ASSERT_EQ(run(kMpm + " simulate --scenario quad-tank-g23-order --samples 4000 --seed 3 --out " + csv), 0);
  std::string reports[3];
  const int threads[3] = {1, 2, 4};
  for (int t = 0; t < 3; ++t) {
    const std::string out = tmp_path("report" + std::to_string(threads[t]) + ".json");
    ASSERT_EQ(std::system((kMpm + " monitor --forgetting 0.999 --plant " + kQuadTank + " --data " + csv +
                           " --json --threads " + std::to_string(threads[t]) + " > " + out + " 2>/dev/null")
                              .c_str()),
              0);
    reports[t] = read_file(out);
  }
  ASSERT_GT(reports[0].size(), 100u);
  EXPECT_NE(reports[0].find("\"alarm\": true"), std::string::npos);  // the planted G23 is raised: a real run
  EXPECT_EQ(reports[1], reports[0]);
  EXPECT_EQ(reports[2], reports[0]);
}

TEST(MonitorCli, RejectsZeroThreads) {
  EXPECT_EQ(WEXITSTATUS(run(kMpm + " monitor --plant " + kQuadTank + " --data /nonexistent.csv --threads 0")), 2);
}

}  // namespace
