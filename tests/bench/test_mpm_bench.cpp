// Runs `mpm bench --json --quick` once and checks the figures' contract:
// every name of issue 4 present, a value or a note saying why not, and zero
// heap allocations per monitor update. Timings are never asserted.
#include <gtest/gtest.h>

#include <cstdio>
#include <map>
#include <optional>
#include <regex>
#include <string>

namespace {

struct Parsed {
  std::string machine;
  std::map<std::string, std::optional<double>> values;
  std::map<std::string, std::string> notes;
  int figures_seen = 0;  // "name" keys, parsed or not
};

std::string run(const std::string& command, int& status) {
  std::string out;
  FILE* p = popen(command.c_str(), "r");
  if (!p) return out;
  char buf[4096];
  while (std::size_t n = std::fread(buf, 1, sizeof buf, p)) out.append(buf, n);
  status = pclose(p);
  return out;
}

Parsed parse(const std::string& json) {
  Parsed p;
  std::smatch m;
  if (std::regex_search(json, m, std::regex(R"re(^\{"machine": "([^"]*)", "figures": \[)re"))) p.machine = m[1];
  const std::regex figure(
      R"re(\{"name": "([a-z0-9_]+)", "value": (null|-?[0-9.eE+-]+), "unit": "[^"]*", "note": "((?:[^"\\]|\\.)*)"\})re");
  for (auto it = std::sregex_iterator(json.begin(), json.end(), figure); it != std::sregex_iterator(); ++it) {
    const std::string name = (*it)[1];
    const std::string value = (*it)[2];
    p.values[name] = value == "null" ? std::nullopt : std::optional<double>(std::stod(value));
    p.notes[name] = (*it)[3];
  }
  for (std::size_t at = json.find("\"name\""); at != std::string::npos; at = json.find("\"name\"", at + 1))
    ++p.figures_seen;
  return p;
}

class MpmBench : public testing::Test {
 protected:
  static void SetUpTestSuite() {
    int status = -1;
    json_ = new std::string(run(std::string(MPM_EXE) + " bench --json --quick 2>/dev/null", status));
    status_ = status;
  }
  static void TearDownTestSuite() { delete json_; }
  static std::string* json_;
  static int status_;
};
std::string* MpmBench::json_ = nullptr;
int MpmBench::status_ = -1;

TEST_F(MpmBench, ExitsCleanlyWithOneJsonObject) {
  EXPECT_EQ(status_, 0);
  ASSERT_FALSE(json_->empty());
  EXPECT_EQ(json_->front(), '{');
  EXPECT_EQ(json_->substr(json_->find_last_not_of("\n") - 1, 2), "]}");
}

TEST_F(MpmBench, EveryFigureParsesAndNamesTheMachine) {
  const Parsed p = parse(*json_);
  EXPECT_FALSE(p.machine.empty());
  EXPECT_EQ(static_cast<int>(p.values.size()), p.figures_seen) << "a figure did not match the expected shape";
}

TEST_F(MpmBench, HasEveryFigureOfTheIssueWithAValueOrAReason) {
  const Parsed p = parse(*json_);
  for (const char* name : {"update_ns_2x2", "update_ns_4x4", "update_ns_20x20", "update_ns_50x50", "batch_ns_2x2",
                           "batch_ratio_2x2", "allocations_per_update", "peak_fraction_50x50",
                           "replay_samples_per_s_2x2", "diagnose_samples_per_s_2x2", "diagnose_peak_rss_mb_2x2",
                           "lcm_latency_p50_us",
                           "lcm_latency_p99_us", "mpmd_rss_mb_2x2", "mpmd_rss_mb_50x50"}) {
    SCOPED_TRACE(name);
    ASSERT_TRUE(p.values.count(name));
    if (!p.values.at(name)) {
      EXPECT_FALSE(p.notes.at(name).empty()) << "unavailable without a reason";
    }
  }
}

TEST_F(MpmBench, MonitorUpdatesAllocateNothing) {
  const Parsed p = parse(*json_);
  ASSERT_TRUE(p.values.count("allocations_per_update"));
  ASSERT_TRUE(p.values.at("allocations_per_update").has_value());
  EXPECT_EQ(*p.values.at("allocations_per_update"), 0.0) << p.notes.at("allocations_per_update");
}

TEST_F(MpmBench, MeasuredTimesArePositive) {  // not a timing assertion: a zero would mean nothing ran
  const Parsed p = parse(*json_);
  for (const char* name :
       {"update_ns_2x2", "update_ns_50x50", "batch_ns_2x2", "replay_samples_per_s_2x2", "diagnose_samples_per_s_2x2"}) {
    SCOPED_TRACE(name);
    ASSERT_TRUE(p.values.count(name) && p.values.at(name).has_value());
    EXPECT_GT(*p.values.at(name), 0.0);
  }
}

// The diagnose throughput is of a diagnosis that worked: `mpm bench` gives it
// a value only when the findings name the channel the scenario planted
// (wood-berry-g21-gain: y2 <- u1), and says so in the note.
TEST_F(MpmBench, DiagnoseFigureIsOfADiagnosisThatFoundThePlantedChannel) {
  const Parsed p = parse(*json_);
  ASSERT_TRUE(p.values.count("diagnose_samples_per_s_2x2"));
  const std::string& note = p.notes.at("diagnose_samples_per_s_2x2");
  ASSERT_TRUE(p.values.at("diagnose_samples_per_s_2x2").has_value()) << note;
  EXPECT_NE(note.find("named the planted channel y2 <- u1"), std::string::npos) << note;
}

// The diagnose command's peak memory is measured on the real command (the
// test runs `mpm bench`, so the child is the mpm beside mpm-bench): a value, and a resident
// set no process of this size has below 1 MB.
TEST_F(MpmBench, DiagnosePeakMemoryIsOfTheRealCommand) {
  const Parsed p = parse(*json_);
  ASSERT_TRUE(p.values.count("diagnose_peak_rss_mb_2x2"));
  const std::string& note = p.notes.at("diagnose_peak_rss_mb_2x2");
  ASSERT_TRUE(p.values.at("diagnose_peak_rss_mb_2x2").has_value()) << note;
  EXPECT_GT(*p.values.at("diagnose_peak_rss_mb_2x2"), 1.0) << note;
  EXPECT_NE(note.find("diagnose --quiet"), std::string::npos) << note;
}

}  // namespace
