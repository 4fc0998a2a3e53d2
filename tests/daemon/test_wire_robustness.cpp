// Issue 12, the wire side of the service: no input can blind the monitor or
// make it misbehave. Each test is a defect measured on the old main:
//   * a malformed sample moved the sequence and session state (seq = 10^15
//     once: every later sample dropped as out of order; a new session every
//     100 malformed samples: samples_used stayed 0);
//   * seq = INT64_MAX was signed overflow, `missing` went negative;
//   * status said ready while nothing had been used for minutes;
//   * a controller_id holding "\n<0>..." became its own emergency line in
//     journald; a SIGHUP storm wrote one line per signal.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <limits>
#include <string>
#include <thread>

#include "child_process.hpp"
#include "config/daemon_config.hpp"
#include "daemon/mpmd/log.hpp"
#include "daemon/mpmd/monitor_service.hpp"
#include "daemon/mpmd/receiver.hpp"
#include "daemon/mpmd/sample_queue.hpp"
#include "daemon/mpmd/sequence_tracker.hpp"
#include "daemon/mpmd/service_loop.hpp"
#include "service_fixture.hpp"
#include "transport/fake_transport.hpp"
#include "transport/message_json.hpp"
#include "wood_berry_stream.hpp"

namespace mpm {
namespace {

using V = SequenceTracker::Verdict;
constexpr std::int64_t kMax = std::numeric_limits<std::int64_t>::max();
constexpr std::int64_t kMin = std::numeric_limits<std::int64_t>::min();

// --- SequenceTracker ----------------------------------------------------------

TEST(SequenceTracker, ExtremeNumbersNeitherOverflowNorGoNegative) {
  // Every pair of these, in both orders: run under UBSan (scripts/test.sh) a
  // signed overflow aborts; in any build `missing` must stay in [0, bound].
  const std::int64_t values[] = {kMin, kMin + 1, -1000000000000000LL, -2, -1, 0, 1, 2, 999999, 1000001,
                                 1000000000000000LL, kMax - 1, kMax};
  for (const std::int64_t a : values) {
    for (const std::int64_t b : values) {
      SequenceTracker t(1000000);
      t.observe(0, a);
      const auto r = t.observe(0, b);
      EXPECT_GE(r.missing, 0) << a << " -> " << b;
      EXPECT_LE(r.missing, 1000000) << a << " -> " << b;
    }
  }
  SequenceTracker t;
  t.observe(0, kMax - 1);
  EXPECT_EQ(t.observe(0, kMax).verdict, V::kNext);
  EXPECT_EQ(t.observe(0, kMax).verdict, V::kDuplicate);
}

TEST(SequenceTracker, ImplausibleJumpsResynchroniseEitherWay) {
  SequenceTracker t(1000);
  t.observe(0, 10);
  EXPECT_EQ(t.observe(0, 10 + 1001).verdict, V::kGap);  // 1000 missing: the bound itself
  EXPECT_EQ(t.observe(0, 1000000000000000LL).verdict, V::kJump);
  EXPECT_EQ(t.observe(0, 1000000000000001LL).verdict, V::kNext);
  EXPECT_EQ(t.observe(0, 5000).verdict, V::kJump) << "far back: resynchronised, not out of order for ever";
  EXPECT_EQ(t.observe(0, 5001).verdict, V::kNext);
  EXPECT_EQ(t.observe(0, 4500).verdict, V::kOutOfOrder) << "a plausible step back is still out of order";
}

// --- MonitorService -------------------------------------------------------------

struct Feed {
  explicit Feed(ServiceSettings settings = test::fast_service())
      : stream(3), service(test::wood_berry_plant(), settings, nullptr) {
    sample.controller_id = settings.controller_id;
    sample.session_id = 42;
  }
  msg::Sample& next_unsent() {
    stream.next(sample);
    sample.sim_y.clear();
    sample.seq = ++seq;
    return sample;
  }
  void feed(int n) {
    for (int k = 0; k < n; ++k) service.on_sample(next_unsent(), now);
  }
  std::uint64_t used() const { return service.monitor().counters().used; }

  std::int64_t seq = 0;
  test::WoodBerryStream stream;
  MonitorService service;
  msg::Sample sample;
  Throttle::Clock::time_point now{};
};

TEST(MonitorServiceWire, MalformedSampleWithAHugeSequenceDoesNotBlindTheService) {
  test::LogCapture logs;
  Feed run;
  run.feed(300);
  msg::Sample bad = run.next_unsent();
  --run.seq;
  bad.seq = 1000000000000000LL;
  bad.u.resize(7);  // malformed
  run.service.on_sample(bad, run.now);
  const auto used = run.used();
  const auto outliers = run.service.monitor().counters().outliers;
  run.feed(300);
  EXPECT_EQ(run.service.counters().malformed, 1u);
  EXPECT_EQ(run.service.counters().out_of_order, 0u);
  EXPECT_EQ(run.service.counters().gaps, 0u);
  // Every valid sample reaches the monitor: used, or screened as an outlier.
  EXPECT_EQ(run.used() + (run.service.monitor().counters().outliers - outliers), used + 300);
}

TEST(MonitorServiceWire, MalformedSamplesWithNewSessionsDoNotStallTheMonitor) {
  Feed run;
  for (int block = 0; block < 20; ++block) {
    run.feed(99);
    msg::Sample bad = run.next_unsent();
    --run.seq;
    bad.session_id = 1000 + block;  // a new session each time
    bad.y.resize(1);
    run.service.on_sample(bad, run.now);
  }
  EXPECT_EQ(run.service.counters().restarts, 0u);
  EXPECT_EQ(run.service.counters().malformed, 20u);
  // The old main used none. Each hole costs the samples whose lags span it
  // (about input_order + 1) and the first 100 settle: most are used.
  EXPECT_GE(run.used(), 1500u);
}

// A malformed sample costs exactly what a lost one costs: the same run with
// that sample simply missing uses the same samples.
TEST(MonitorServiceWire, AHugeSimulatedOutputOnceCostsNoMoreThanALostSample) {
  Feed run, baseline;
  run.feed(200);
  baseline.feed(200);
  msg::Sample bad = run.next_unsent();
  bad.sim_y.assign(1000000, 1.0);
  run.service.on_sample(bad, run.now);
  baseline.next_unsent();  // drawn, never sent
  run.feed(300);
  baseline.feed(300);
  EXPECT_EQ(run.service.counters().malformed, 1u);
  EXPECT_EQ(run.service.counters().gaps, 0u) << "counted as malformed, not also as missing";
  EXPECT_EQ(baseline.service.counters().gaps, 1u);
  EXPECT_EQ(run.used(), baseline.used());
  EXPECT_GT(run.used(), 150u);
}

TEST(MonitorServiceWire, AValidSampleWithAnImplausibleJumpIsResynchronisedAndLogged) {
  test::LogCapture logs;
  Feed run, baseline;
  run.feed(300);
  baseline.feed(300);
  run.seq = 1000000000000000LL;  // a renumbered (or hostile) publisher
  run.feed(1);
  baseline.sample.session_id = 43;  // the same, as two publisher restarts
  baseline.feed(1);
  run.seq = 301;  // back to the real numbering
  baseline.sample.session_id = 44;
  const auto before = run.used();
  run.feed(300);
  baseline.feed(300);
  const ServiceCounters& c = run.service.counters();
  EXPECT_EQ(c.jumps, 2u);
  EXPECT_EQ(c.out_of_order, 0u);
  EXPECT_EQ(c.missing, 0u);
  // The old main dropped every later sample; now a jump costs what a
  // publisher restart costs (a settle time), no more.
  EXPECT_EQ(run.used(), baseline.used());
  EXPECT_GT(run.used(), before + 50) << "never a permanent drop";
  EXPECT_EQ(logs.count("sequence jumped"), 1) << "logged, throttled";
  msg::Status status;
  run.service.fill_status(status, 0, 0);
  EXPECT_GE(status.missing, 0);
  EXPECT_EQ(status.restarts, 2);
}

TEST(MonitorServiceWire, StatusIsNotReadyWhenNothingWasUsableForStaleAfter) {
  test::LogCapture logs;
  ServiceSettings settings = test::fast_service();
  settings.stale_after = 30;
  Feed run(settings);
  const auto t0 = Throttle::Clock::time_point{} + std::chrono::hours(1);
  run.now = t0;
  run.service.check_health(t0);
  run.feed(800);
  run.service.check_health(t0 + std::chrono::seconds(29));
  msg::Status status;
  run.service.fill_status(status, 0, 0);
  ASSERT_TRUE(status.ready);
  EXPECT_FALSE(run.service.stale());

  // Samples keep coming but all are malformed: still stale after 30 s.
  run.now = t0 + std::chrono::seconds(10);
  for (int k = 0; k < 50; ++k) {
    msg::Sample& s = run.next_unsent();
    s.u.resize(3);
    run.service.on_sample(s, run.now);
  }
  run.service.check_health(t0 + std::chrono::seconds(41));
  run.service.fill_status(status, 0, 0);
  EXPECT_FALSE(status.ready);
  EXPECT_EQ(logs.count("no usable sample for more than 30 s"), 1);
  run.service.check_health(t0 + std::chrono::seconds(50));
  EXPECT_EQ(logs.count("no usable sample"), 1) << "logged on the change only";

  run.now = t0 + std::chrono::seconds(51);
  run.feed(1);
  run.service.check_health(run.now);
  run.service.fill_status(status, 0, 0);
  EXPECT_TRUE(status.ready);
  EXPECT_EQ(logs.count("usable samples again"), 1);
}

TEST(MonitorServiceWire, NeverAnySampleIsStaleWithAReason) {
  test::LogCapture logs;
  ServiceSettings settings = test::fast_service();
  settings.stale_after = 5;
  Feed run(settings);
  run.service.check_health(run.now);
  run.service.check_health(run.now + std::chrono::seconds(6));
  EXPECT_TRUE(run.service.stale());
  EXPECT_EQ(logs.count("no sample of this controller has arrived"), 1);
}

// --- logs and JSON --------------------------------------------------------------

TEST(LogEscaping, WireStringsCannotStartAJournalLine) {
  test::LogCapture logs;
  Feed run;
  msg::Sample s = run.next_unsent();
  s.controller_id = "evil\n<0>emergency\r\x1b[2J\x7f";
  run.service.on_sample(s, run.now);
  ASSERT_EQ(logs.lines.size(), 1u);
  const std::string& line = logs.lines[0];
  for (const char c : line) {
    EXPECT_FALSE(static_cast<unsigned char>(c) < 0x20 || c == 0x7f) << "control character in: " << line;
  }
  EXPECT_NE(line.find("evil\\x0a<0>emergency\\x0d\\x1b[2J\\x7f"), std::string::npos) << line;
}

TEST(LogEscaping, EscapeNeverOverflowsItsBuffer) {
  const std::string in(100, '\n');
  char out[41];
  const std::size_t n = log::escape_controls(in.data(), in.size(), out, sizeof out);
  EXPECT_LE(n, 40u);
  EXPECT_EQ(n % 4, 0u);
  EXPECT_EQ(out[n], '\0');
}

TEST(MessageJson, NumbersAreAlwaysFiniteAndStringsEscaped) {
  msg::Status s;
  s.controller_id = "a\nb\"c";
  s.effective_samples = std::numeric_limits<double>::quiet_NaN();
  s.raise_threshold = std::numeric_limits<double>::infinity();
  s.clear_threshold = -std::numeric_limits<double>::infinity();
  s.channels.resize(1);
  s.channels[0].f_pairwise = std::numeric_limits<double>::quiet_NaN();
  s.channels[0].gamma = 1e308 * 10;
  s.loops.resize(1);
  s.loops[0].sigma1 = -std::numeric_limits<double>::quiet_NaN();
  msg::Sample sample;
  sample.u = {std::numeric_limits<double>::infinity(), 1.0};
  sample.extra_names = {"x\ty"};
  sample.extra_values = {std::numeric_limits<double>::quiet_NaN()};
  msg::Alarm alarm;
  alarm.f = std::numeric_limits<double>::quiet_NaN();
  alarm.gamma = std::numeric_limits<double>::infinity();
  for (const std::string& json : {msg::to_json(s), msg::to_json(sample), msg::to_json(alarm)}) {
    for (const char* bad : {":nan", ":-nan", ":inf", ":-inf", "[nan", "[-nan", "[inf", "[-inf", ",nan", ",-nan",
                            ",inf", ",-inf"}) {
      EXPECT_EQ(json.find(bad), std::string::npos) << bad << " in " << json;
    }
    for (const char c : json) EXPECT_GE(static_cast<unsigned char>(c), 0x20) << json;
  }
  EXPECT_NE(msg::to_json(s).find("\"effective_samples\":null"), std::string::npos);
  EXPECT_NE(msg::to_json(s).find("\"a\\nb\\\"c\""), std::string::npos);
}

// --- SIGHUP storm -----------------------------------------------------------------

TEST(ServiceLoopReload, ASighupStormIsLoggedAtALimitedRate) {
  test::LogCapture logs;
  auto bus = transport::make_fake_bus();
  auto transport = transport::make_fake_transport(bus);
  SampleQueue queue(16);
  Receiver receiver(*transport, queue);
  Notifier notifier;
  LoadedConfig loaded = test::wood_berry_config(3600);
  std::string error;
  auto service = make_service(loaded, nullptr, error);
  ASSERT_TRUE(service) << error;
  ASSERT_TRUE(receiver.start(error)) << error;
  // The configuration file does not exist: every reload fails and says so.
  ServiceLoop loop("/nonexistent/mpmd-reload-storm.yaml", loaded, std::move(service), queue, receiver, *transport,
                   notifier);
  std::atomic<bool> stop{false}, reload{false};
  std::thread thread([&] { loop.run(stop, reload); });
  for (int k = 0; k < 10; ++k) {
    reload = true;
    ASSERT_TRUE(test::eventually([&] { return !reload.load(); }));
  }
  stop = true;
  thread.join();
  receiver.stop();
  EXPECT_EQ(logs.count("reload failed"), 1);
}

// --- configuration -------------------------------------------------------------

TEST(WireSettings, ReadFromTheConfigurationWithLocatedErrors) {
  const std::string base = "controller_id: wb\nplant: wood-berry.yaml\n";
  const auto c = config::parse_daemon_config(base + "max_sequence_jump: 500\nstale_after: 12.5\n", "t.yaml",
                                             MPM_SOURCE_DIR "/config");
  EXPECT_EQ(c.max_sequence_jump, 500);
  EXPECT_EQ(c.stale_after, 12.5);
  const auto d = config::parse_daemon_config(base + "stale_after: auto\n", "t.yaml", MPM_SOURCE_DIR "/config");
  EXPECT_EQ(d.stale_after, -1.0);
  EXPECT_EQ(d.max_sequence_jump, SequenceTracker::kDefaultMaxJump);
  for (const char* bad : {"max_sequence_jump: 0\n", "max_sequence_jump: 2.5\n", "stale_after: -3\n"}) {
    try {
      config::parse_daemon_config(base + bad, "t.yaml", MPM_SOURCE_DIR "/config");
      ADD_FAILURE() << "accepted " << bad;
    } catch (const std::exception& e) {
      EXPECT_NE(std::string(e.what()).find("t.yaml:3:"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace mpm
