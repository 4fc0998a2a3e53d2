// `mpm monitor` end to end: the replay split over threads (each a part of
// the outputs) gives the report one thread gives, byte for byte.
#include <cstdlib>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "support/cli.hpp"

namespace {

using namespace mpm::test;  // kMpm, config_file, read_file, run_quietly, ...

const std::string kQuadTank = config_file("quad-tank-4x4.yaml");

std::string tmp_path(const std::string& name) { return mpm::test::tmp_path("mpm_monitor_", name); }

TEST(MonitorCli, ThreadsDoNotChangeTheReport) {
  const std::string csv = tmp_path("g23.csv");
  ASSERT_EQ(run_quietly(kMpm + " simulate --scenario quad-tank-g23-order --samples 4000 --seed 3 --out " + csv), 0);
  std::string reports[3];
  const int threads[3] = {1, 2, 4};
  for (int t = 0; t < 3; ++t) {
    const std::string out = tmp_path("report" + std::to_string(threads[t]) + ".json");
    ASSERT_EQ(std::system((kMpm + " monitor --plant " + kQuadTank + " --data " + csv +
                           " --json --threads " + std::to_string(threads[t]) + " > " + out + " 2>/dev/null")
                              .c_str()),
              0);
    reports[t] = read_file(out);
  }
  ASSERT_GT(reports[0].size(), 100u);
  EXPECT_NE(reports[0].find("\"mismatch\": true"), std::string::npos);  // the planted G23 is found: a real run
  EXPECT_EQ(reports[1], reports[0]);
  EXPECT_EQ(reports[2], reports[0]);
}

TEST(MonitorCli, JsonHasNoNanOrInfinityAfterHugeValues) {
  // A recording whose y1 holds 1e300 for ten samples (accepted as a level,
  // the factor overflows and the output restarts): every number printed is
  // finite or null.
  const std::string csv = tmp_path("huge.csv");
  const std::string plant = config_file("wood-berry.yaml");
  ASSERT_EQ(run_quietly(kMpm + " simulate --scenario wood-berry-nominal --samples 3000 --seed 2 --out " + csv), 0);
  std::string text = read_file(csv), edited;
  std::size_t line = 0, pos = 0, y1 = 0;
  {
    const std::string header = text.substr(0, text.find('\n'));
    std::size_t col = 0;
    for (std::size_t i = 0, start = 0; i <= header.size(); ++i)
      if (i == header.size() || header[i] == ',') {
        if (header.substr(start, i - start) == "y1") y1 = col;
        ++col;
        start = i + 1;
      }
  }
  ASSERT_GT(y1, 0u);
  while (pos < text.size()) {
    const std::size_t end = text.find('\n', pos);
    std::string row = text.substr(pos, end - pos);
    if (line >= 1500 && line < 1510) {
      std::size_t c = 0, s0 = 0;
      for (std::size_t k = 0; k < y1; ++k) s0 = row.find(',', s0) + 1;
      c = row.find(',', s0);
      row = row.substr(0, s0) + "1e300" + (c == std::string::npos ? "" : row.substr(c));
    }
    edited += row + "\n";
    ++line;
    if (end == std::string::npos) break;
    pos = end + 1;
  }
  const std::string huge = tmp_path("huge_edited.csv");
  std::ofstream(huge) << edited;
  const std::string out = tmp_path("huge.json");
  ASSERT_EQ(std::system((kMpm + " monitor --forgetting 0.999 --plant " + plant + " --data " + huge + " --json > " + out +
                         " 2>/dev/null").c_str()),
            0);
  const std::string json = read_file(out);
  ASSERT_GT(json.size(), 100u);
  for (const char* bad : {"nan", "NaN", "inf", "Inf"}) EXPECT_EQ(json.find(bad), std::string::npos) << bad << " in " << json;
  EXPECT_NE(json.find("\"resets\": "), std::string::npos);
}

TEST(MonitorCli, EventsAreJsonLinesOfRaises) {
  const std::string csv = tmp_path("g21.csv");
  const std::string plant = config_file("wood-berry.yaml");
  ASSERT_EQ(run_quietly(kMpm + " simulate --scenario wood-berry-g21-gain --samples 12000 --seed 1 --out " + csv), 0);
  const std::string out = tmp_path("events.jsonl");
  ASSERT_EQ(std::system((kMpm + " monitor --forgetting 0.999 --plant " + plant + " --data " + csv + " --events > " + out +
                         " 2>/dev/null").c_str()),
            0);
  const std::string events = read_file(out);
  ASSERT_EQ(events.rfind("{\"event\": \"raised\"", 0), 0u) << events;
  EXPECT_NE(events.find("\"output\": \"y2\", \"channel\": \"u1\""), std::string::npos) << events;
  EXPECT_EQ(events.find("\"output\": \"y1\""), std::string::npos) << "y1 matches the model: " << events;
}

TEST(MonitorCli, RejectsZeroThreads) {
  EXPECT_EQ(WEXITSTATUS(run_quietly(kMpm + " monitor --plant " + kQuadTank + " --data /nonexistent.csv --threads 0")),
            2);
}

}  // namespace

namespace {

// The loaders' caps from --max-... flags (daemon/limit_flags.hpp): a plant
// with a delay beyond the default cap is a located error, loads with the cap
// raised; a bad cap is a usage error naming the flag and its range.
TEST(MonitorCli, LimitFlagsSetTheLoadersCaps) {
  const std::string csv = tmp_path("wb.csv");
  ASSERT_EQ(run_quietly(kMpm + " simulate --scenario wood-berry-nominal --samples 2000 --seed 1 --out " + csv), 0);
  std::string plant = read_file(config_file("wood-berry.yaml"));
  const auto at = plant.find("delay: 8");
  ASSERT_NE(at, std::string::npos);
  plant.replace(at, 8, "delay: 1500");
  const std::string slow = tmp_path("slow.yaml");
  std::ofstream(slow) << plant;
  const std::string err = tmp_path("err.txt");
  const std::string cmd = kMpm + " monitor --plant " + slow + " --data " + csv;
  EXPECT_EQ(WEXITSTATUS(std::system((cmd + " > /dev/null 2> " + err).c_str())), 1);
  EXPECT_NE(read_file(err).find("model[2].delay: expected a delay in 0..1000 samples, got 1500"), std::string::npos)
      << read_file(err);
  EXPECT_EQ(run_quietly(cmd + " --max-delay-samples 2000"), 0);
  EXPECT_EQ(WEXITSTATUS(std::system((cmd + " --max-delay-samples 1e9 > /dev/null 2> " + err).c_str())), 2);
  EXPECT_NE(read_file(err).find("--max-delay-samples: expected a whole number in 0..10000000"), std::string::npos)
      << read_file(err);
  EXPECT_EQ(WEXITSTATUS(run_quietly(cmd + " --max-csv-columns 3")), 1) << "7 columns over a cap of 3";
}

}  // namespace
