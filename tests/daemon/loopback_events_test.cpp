// One front end, live and offline: `mpm monitor --events` prints exactly the
// raise and clear events mpmd publishes for the same samples and settings.
// The closed-loop Wood-Berry column under its MPC with G21's gain set to
// 3 x nominal (mpm simulate, scenario wood-berry-g21-gain: a mismatch the
// live detector raises within the record) is replayed offline by `mpm
// monitor --events` and published sample by sample into mpmd over the
// transport; the alarms mpmd publishes must be the same events: sample,
// output, channel, raised or cleared, and the numbers (statistic, threshold,
// F, p, gamma) to 1e-9 relative. Both detectors run (mpmd's defaults): the
// sequential detector's events in order; the diagnosis scan's (published by
// mpmd when its diagnosis thread finishes a look, so possibly after later
// sequential alarms) compared as a set keyed by sample and output, with the
// channel, the physics word and the look's level.
#include <cmath>
#include <fstream>
#include <map>
#include <tuple>
#include <sstream>

#include "config/plant_loader.hpp"
#include "loopback_fixture.hpp"

namespace mpm::test {
namespace {

// The settings both sides use, as mpmd's YAML and as `mpm monitor`'s flags.
constexpr const char* kForgetting = "0.999";
constexpr const char* kSettle = "150";
constexpr int kSamples = 3000;

struct Event {
  bool raised = false;
  std::int64_t sample = 0;
  std::string output, channel, detector, physics;
  double statistic = 0, threshold = 0, f = 0, p = 0, gamma = 0;
};

// The raw text of `"key": value` in a JSON line of `mpm monitor --events`.
std::string json_value(const std::string& line, const std::string& key) {
  const std::string tag = "\"" + key + "\": ";
  const std::size_t at = line.find(tag);
  if (at == std::string::npos) return "";
  std::size_t begin = at + tag.size(), end = begin;
  if (line[begin] == '"') {
    end = line.find('"', begin + 1);
    return line.substr(begin + 1, end - begin - 1);
  }
  while (end < line.size() && line[end] != ',' && line[end] != '}') ++end;
  return line.substr(begin, end - begin);
}

double number(const std::string& text) { return text == "null" || text.empty() ? std::nan("") : std::stod(text); }

std::vector<Event> read_events(const std::string& text) {
  std::vector<Event> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    Event e;
    e.raised = json_value(line, "event") == "raised";
    e.sample = std::stoll(json_value(line, "sample"));
    e.output = json_value(line, "output");
    e.channel = json_value(line, "channel");
    e.statistic = number(json_value(line, "statistic"));
    e.threshold = number(json_value(line, "threshold"));
    e.f = number(json_value(line, "F_conditional"));
    e.p = number(json_value(line, "p_value"));
    e.gamma = number(json_value(line, "gamma"));
    e.detector = json_value(line, "detector");
    e.physics = json_value(line, "physics");
    out.push_back(e);
  }
  return out;
}

// mpmd's raise text: "... score S > H over W samples ...".
bool score_in_text(const std::string& text, double& score, double& threshold) {
  const std::size_t at = text.find(": score ");
  return at != std::string::npos && std::sscanf(text.c_str() + at, ": score %lf > %lf", &score, &threshold) == 2;
}

::testing::AssertionResult close(double a, double b) {
  if (std::isnan(a) && std::isnan(b)) return ::testing::AssertionSuccess();
  if (std::abs(a - b) <= 1e-9 * std::max(std::abs(a), std::abs(b))) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << a << " vs " << b;
}

class EventsTest : public LoopbackTest {};

TEST_P(EventsTest, MonitorEventsAreExactlyTheAlarmsMpmdPublishes) {
  const std::string csv = dir().file("run.csv");
  ChildProcess sim({kMpm, "simulate", "--scenario", "wood-berry-g21-gain", "--edit", "y2.u1.gain=3", "--samples",
                    std::to_string(kSamples), "--seed", "1", "--out", csv},
                   dir().file("sim.out"), dir().file("sim.err"));
  ASSERT_EQ(sim.wait_exit(std::chrono::seconds(60)), 0) << sim.stderr_text();
  const std::string plant_file = MPM_SOURCE_DIR "/config/wood-berry.yaml";

  // Offline.
  ChildProcess monitor({kMpm, "monitor", "--plant", plant_file, "--data", csv, "--events", "--forgetting", kForgetting,
                        "--settle-samples", kSettle},
                       dir().file("monitor.out"), dir().file("monitor.err"));
  ASSERT_EQ(monitor.wait_exit(std::chrono::seconds(60)), 0) << monitor.stderr_text();
  const std::vector<Event> events = read_events(monitor.stdout_text());
  ASSERT_FALSE(events.empty()) << "the scenario must raise within " << kSamples << " samples";
  EXPECT_TRUE(events.front().raised && events.front().output == "y2" && events.front().channel == "u1")
      << monitor.stdout_text();

  // Live: the same samples, sequence number = row index, every one seen.
  const std::string live_monitor =
      std::string("monitor: {forgetting: ") + kForgetting + ", settle_samples: " + kSettle + "}\n";
  Session run = open_session(write_config("mpmd.yaml", "wb", live_monitor), "wb", 0);
  ASSERT_TRUE(run.up) << run.log();
  const PlantModel plant = config::load_plant(plant_file);
  const config::Recording rec = config::load_recording(csv);
  const config::BoundRecording bound = config::bind(plant, rec);
  ASSERT_EQ(rec.samples(), static_cast<std::size_t>(kSamples));
  msg::Sample s;
  s.controller_id = "wb";
  s.session_id = 77;
  s.u.resize(2);
  s.y.resize(2);
  std::int64_t sent = 0;
  for (Eigen::Index k = 0; k < static_cast<Eigen::Index>(rec.samples()); ++k) {
    s.seq = k;
    for (std::size_t i = 0; i < 2; ++i) s.u[i] = rec.data(k, static_cast<Eigen::Index>(bound.inputs[i]));
    for (std::size_t j = 0; j < 2; ++j) s.y[j] = rec.data(k, static_cast<Eigen::Index>(bound.outputs[j]));
    ASSERT_TRUE(run.t->publish(s));
    ++sent;
    if (sent % 50 == 0 || sent == kSamples) {
      ASSERT_TRUE(run.obs->wait_status("wb", [sent](const msg::Status& st) { return st.samples_seen >= sent; }))
          << "sample " << k << ": " << run.mpmd->stderr_text();
    }
  }
  const msg::Status status = *run.obs->status("wb");
  EXPECT_EQ(status.samples_seen, kSamples);
  EXPECT_EQ(status.gaps + status.duplicates + status.out_of_order + status.malformed + status.dropped, 0);
  // An alarm goes out before the status that counts its sample; two more
  // status periods let any late one arrive before the count is compared.
  ASSERT_TRUE(run.obs->wait_alarms([&](const auto& a) { return a.size() >= events.size(); }, std::chrono::seconds(20)));
  const int statuses = run.obs->status_count("wb");
  ASSERT_TRUE(eventually([&] { return run.obs->status_count("wb") >= statuses + 2; }, std::chrono::seconds(10)));

  ASSERT_EQ(run.obs->alarms().size(), events.size()) << monitor.stdout_text();
  // The scan's events, as a set keyed by (sample, output, raised).
  std::vector<msg::Alarm> alarms, scan_alarms;
  for (const msg::Alarm& a : run.obs->alarms()) {
    (a.text.rfind("diagnosis scan:", 0) == 0 ? scan_alarms : alarms).push_back(a);
  }
  std::map<std::tuple<std::int64_t, std::string, bool>, Event> scan_events;
  std::vector<Event> sequential;
  for (const Event& e : events) {
    if (e.detector == "scan") scan_events[{e.sample, e.output, e.raised}] = e;
    else sequential.push_back(e);
  }
  EXPECT_FALSE(scan_events.empty()) << "the scan must raise the scenario too";
  ASSERT_EQ(scan_alarms.size(), scan_events.size()) << monitor.stdout_text();
  for (const msg::Alarm& a : scan_alarms) {
    SCOPED_TRACE(a.text);
    const auto it = scan_events.find({a.sample_sequence, a.output, a.raised});
    ASSERT_NE(it, scan_events.end());
    const Event& e = it->second;
    EXPECT_EQ(a.input, e.channel == "null" ? "" : e.channel);
    EXPECT_EQ(a.physics, e.raised ? e.physics : "");
    EXPECT_TRUE(close(a.p_value, e.p));  // the look's level
  }
  ASSERT_EQ(alarms.size(), sequential.size()) << monitor.stdout_text();
  for (std::size_t n = 0; n < sequential.size(); ++n) {
    const Event& e = sequential[n];
    const msg::Alarm& a = alarms[n];
    SCOPED_TRACE("event " + std::to_string(n) + ": " + a.text);
    EXPECT_EQ(a.controller_id, "wb");
    EXPECT_EQ(a.raised, e.raised);
    EXPECT_EQ(a.sample_sequence, e.sample);
    EXPECT_EQ(a.output, e.output);
    EXPECT_EQ(a.input, e.channel);
    EXPECT_TRUE(close(a.f, e.f));
    EXPECT_TRUE(close(a.p_value, e.p));
    EXPECT_TRUE(close(a.gamma, e.gamma));
    if (e.raised) {
      double score = 0, threshold = 0;
      ASSERT_TRUE(score_in_text(a.text, score, threshold));
      EXPECT_TRUE(close(score, e.statistic));
      EXPECT_TRUE(close(threshold, e.threshold));
    }
  }
  std::printf("%zu events, the first: %s\n", events.size(), alarms.front().text.c_str());

  run.mpmd->signal(SIGTERM);
  EXPECT_EQ(run.mpmd->wait_exit(std::chrono::seconds(20)), 0);
}

INSTANTIATE_TEST_SUITE_P(Transports, EventsTest, ::testing::Values(transport::Kind::kLcm, transport::Kind::kDds),
                         kind_name);

}  // namespace
}  // namespace mpm::test
