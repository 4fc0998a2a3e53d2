// MonitorService without any transport: planted mismatch found on exactly its
// channel and cleared when the plant returns; data-quality problems counted,
// logged once, and survived with the statistics kept.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "daemon/mpmd/monitor_service.hpp"
#include "service_fixture.hpp"
#include "support/alloc_counter.hpp"
#include "wood_berry_stream.hpp"

namespace mpm {
namespace {

using test::WoodBerryStream;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A service fed from the Wood-Berry stream, recording the alarms it emits
// with the sequence number current when each came.
struct Feed {
  explicit Feed(ServiceSettings settings = test::fast_service(), std::uint64_t seed = 7)
      : stream(seed),
        service(test::wood_berry_plant(), settings, [this](const msg::Alarm& a) { alarms.push_back({seq, a}); }) {
    sample.controller_id = settings.controller_id;
    sample.session_id = 42;
  }

  // `n` samples of the stream with consecutive sequence numbers.
  void feed(int n) {
    for (int k = 0; k < n; ++k) next();
  }
  // The next stream sample, not yet sent (tests damage it first).
  msg::Sample& next_unsent() {
    stream.next(sample);
    sample.sim_y.clear();
    sample.seq = ++seq;
    return sample;
  }
  void next() { send(next_unsent()); }
  void send(const msg::Sample& s) { service.on_sample(s, now); }

  struct Seen {
    std::int64_t at;
    msg::Alarm alarm;
  };
  std::int64_t seq = 0;
  WoodBerryStream stream;
  std::vector<Seen> alarms;
  MonitorService service;
  msg::Sample sample;
  Throttle::Clock::time_point now{};
};

TEST(MonitorService, MatchedPlantRaisesNothing) {
  Feed run;
  run.feed(4000);
  EXPECT_TRUE(run.alarms.empty());
  EXPECT_TRUE(run.service.monitor().ready());
  EXPECT_EQ(run.service.counters().seen, 4000u);
  // Settle samples skip the monitor; its regressors fill before any update.
  const auto used = run.service.monitor().counters().used;
  EXPECT_LE(used, 4000u - 100u);
  EXPECT_GE(used, 4000u - 100u - 300u);
}

TEST(MonitorService, G21GainMismatchRaisesOnlyU1ToY2AndClears) {
  Feed run;
  run.feed(1000);
  ASSERT_TRUE(run.service.monitor().ready());
  ASSERT_TRUE(run.alarms.empty());

  run.stream.set_g21_gain(1.2);
  const std::int64_t onset = run.seq;
  run.feed(1000);
  ASSERT_EQ(run.alarms.size(), 1u) << "exactly one channel raised";
  const auto& raised = run.alarms[0];
  EXPECT_TRUE(raised.alarm.raised);
  EXPECT_EQ(raised.alarm.controller_id, "wb");
  EXPECT_EQ(raised.alarm.output, "y2");
  EXPECT_EQ(raised.alarm.input, "u1");
  EXPECT_EQ(raised.alarm.output_index, 1);
  EXPECT_EQ(raised.alarm.input_index, 0);
  EXPECT_EQ(raised.alarm.sample_sequence, raised.at);
  EXPECT_LT(raised.alarm.p_value, 1e-5);
  EXPECT_GT(raised.alarm.f, 0.0);
  EXPECT_NE(raised.alarm.text.find("u1 -> y2"), std::string::npos);
  EXPECT_LT(raised.at - onset, 600) << "raised within a bounded number of samples";

  run.stream.set_g21_gain(1.0);
  const std::int64_t back = run.seq;
  // The output clears once every detector window has forgotten the
  // mismatch: within a few memories of the longest.
  const auto& det = run.service.monitor().detector();
  const auto longest = static_cast<std::int64_t>(det.window(det.windows() - 1));
  for (std::int64_t fed = 0; fed < 4 * longest && run.alarms.size() < 2; fed += 500) run.feed(500);
  ASSERT_EQ(run.alarms.size(), 2u) << "only the clear of the same channel follows";
  EXPECT_FALSE(run.alarms[1].alarm.raised);
  EXPECT_EQ(run.alarms[1].alarm.input, "u1");
  EXPECT_EQ(run.alarms[1].alarm.output, "y2");
  EXPECT_LT(run.alarms[1].at - back, 4 * longest);
}

TEST(MonitorService, StatusReflectsTheMonitor) {
  Feed run;
  run.stream.set_g21_gain(1.5);
  run.feed(1500);
  msg::Status status;
  run.service.fill_status(status, 123, 456);
  EXPECT_EQ(status.controller_id, "wb");
  EXPECT_EQ(status.utime, 123);
  EXPECT_EQ(status.uptime_ms, 456);
  EXPECT_TRUE(status.ready);
  EXPECT_EQ(status.samples_seen, 1500);
  ASSERT_EQ(status.channels.size(), 4u);  // output-major: y1u1 y1u2 y2u1 y2u2
  ASSERT_EQ(status.loops.size(), 2u);
  EXPECT_EQ(status.channels[2].output, "y2");
  EXPECT_EQ(status.channels[2].input, "u1");
  EXPECT_TRUE(status.channels[2].alarm);
  EXPECT_EQ(status.alarms_raised, 1);
  EXPECT_TRUE(status.loops[1].alarm);
  EXPECT_FALSE(status.loops[0].alarm);
  EXPECT_GT(status.channels[2].lr, status.raise_threshold);
  EXPECT_DOUBLE_EQ(status.channels[2].lr, run.service.monitor().channel(1, 0).lr_conditional);
}

TEST(MonitorService, RetiringClearsTheRaisedAlarms) {
  Feed run;
  run.stream.set_g21_gain(1.5);
  run.feed(1500);
  ASSERT_EQ(run.alarms.size(), 1u);
  run.service.retire("reloaded");
  ASSERT_EQ(run.alarms.size(), 2u);
  EXPECT_FALSE(run.alarms[1].alarm.raised);
  EXPECT_EQ(run.alarms[1].alarm.input, "u1");
  EXPECT_EQ(run.alarms[1].alarm.output, "y2");
  EXPECT_NE(run.alarms[1].alarm.text.find("reloaded"), std::string::npos);
  EXPECT_GT(run.alarms[1].alarm.utime, 0) << "the time of the retirement";
  run.service.retire("again");
  EXPECT_EQ(run.alarms.size(), 2u) << "nothing raised any more";
}

TEST(MonitorService, SequenceProblemsAreCountedLoggedOnceAndSurvived) {
  test::LogCapture logs;
  Feed run;
  run.feed(600);
  const double n_eq = run.service.monitor().effective_samples();
  ASSERT_GT(n_eq, 100.0);

  // Two gaps (3 and 2 samples lost).
  for (int gap : {3, 2}) {
    run.seq += gap;
    run.next();
  }
  // Two duplicates of the last sample.
  run.send(run.sample);
  run.send(run.sample);
  // Out of order: 2 ahead first, then the one skipped.
  msg::Sample skipped = run.next_unsent();
  run.next();
  run.send(skipped);
  // The publisher restarts: new session, numbering from 1.
  run.sample.session_id = 43;
  run.seq = 0;
  run.feed(5);

  const ServiceCounters& c = run.service.counters();
  EXPECT_EQ(c.gaps, 3u);  // two planted + the hole the out-of-order sample left
  EXPECT_EQ(c.missing, 6u);
  EXPECT_EQ(c.duplicates, 2u);
  EXPECT_EQ(c.out_of_order, 1u);
  EXPECT_EQ(c.restarts, 1u);
  EXPECT_EQ(logs.count("samples missing"), 1);
  EXPECT_EQ(logs.count("duplicate"), 1);
  EXPECT_EQ(logs.count("arrived after"), 1);
  EXPECT_EQ(logs.count("restarted"), 1);
  // Statistics kept: the monitor was not reset.
  EXPECT_GE(run.service.monitor().effective_samples(), n_eq * 0.9);
  EXPECT_TRUE(run.service.monitor().ready());
}

TEST(MonitorService, WrongSizedAndNaNSamplesAreCountedAndLoggedOnce) {
  test::LogCapture logs;
  Feed run;
  run.feed(600);
  const auto used_before = run.service.monitor().counters().used;
  for (int k = 0; k < 3; ++k) {
    msg::Sample& s = run.next_unsent();
    s.u.push_back(1.0);  // three inputs for a two-input plant
    run.send(s);
  }
  for (int k = 0; k < 2; ++k) {
    msg::Sample& s = run.next_unsent();
    s.y.resize(1);
    run.send(s);
  }
  {
    msg::Sample& s = run.next_unsent();
    s.sim_y = {1.0};  // must be empty or one per output
    run.send(s);
  }
  for (int k = 0; k < 4; ++k) {
    msg::Sample& s = run.next_unsent();
    s.y[1] = kNaN;
    run.send(s);
  }
  run.feed(400);
  const ServiceCounters& c = run.service.counters();
  EXPECT_EQ(c.malformed, 6u);
  EXPECT_EQ(c.nan_samples, 4u);
  EXPECT_EQ(c.gaps, 0u) << "a malformed sample is not a sequence gap";
  EXPECT_EQ(logs.count("has 3 inputs"), 1) << "first malformed sample logged, the rest throttled";
  EXPECT_EQ(logs.count("the plant has"), 1);
  EXPECT_EQ(logs.count("NaN"), 1);
  EXPECT_GT(run.service.monitor().counters().used, used_before + 150) << "keeps monitoring";
  EXPECT_GE(run.service.monitor().counters().missing, 4u) << "NaN samples reach the monitor as missing";
}

TEST(MonitorService, ThrottledLogReportsSuppressedCountAfterTheInterval) {
  test::LogCapture logs;
  ServiceSettings settings = test::fast_service();
  settings.log_interval = 10.0;
  Feed run(settings);
  run.feed(10);
  run.send(run.sample);  // duplicate: logged
  run.send(run.sample);  // suppressed
  run.send(run.sample);  // suppressed
  run.now += std::chrono::seconds(11);
  run.send(run.sample);  // logged with the two suppressed
  EXPECT_EQ(logs.count("duplicate"), 2);
  EXPECT_EQ(logs.count("2 more since the last report"), 1);
}

TEST(MonitorService, OtherControllersAreIgnored) {
  test::LogCapture logs;
  Feed run;
  run.feed(300);
  msg::Sample other = run.sample;
  other.controller_id = "another";
  for (int k = 0; k < 5; ++k) {
    other.seq = 1000 + k;
    run.send(other);
  }
  run.feed(10);
  EXPECT_EQ(run.service.counters().foreign, 5u);
  EXPECT_EQ(run.service.counters().seen, 310u);
  EXPECT_EQ(run.service.counters().gaps, 0u);
  EXPECT_EQ(logs.count("another"), 1);
}

TEST(MonitorService, SimulatedOutputsGiveTheResidual) {
  // The controller sends sim_y = y minus a planted residual: the monitor must
  // see exactly that residual, whatever the nominal model would say.
  ServiceSettings settings = test::fast_service();
  settings.settle_samples = 0;
  settings.plain_lags = true;  // the planted link is one plain lag
  Feed run(settings);
  std::mt19937_64 rng(3);
  std::normal_distribution<double> white;
  double last_u1 = 0.0;
  for (int k = 0; k < 1500; ++k) {
    msg::Sample& s = run.next_unsent();
    // Residual of y2 = 0.16 u1(k-1) + noise: a planted causal link. y1's
    // residual is white noise.
    s.sim_y = {s.y[0] - white(rng), s.y[1] - (0.16 * last_u1 + white(rng))};
    last_u1 = s.u[0];
    run.send(s);
  }
  ASSERT_EQ(run.alarms.size(), 1u);
  EXPECT_EQ(run.alarms[0].alarm.output, "y2");
  EXPECT_EQ(run.alarms[0].alarm.input, "u1");
}

TEST(MonitorService, SteadyStateSamplesDoNotAllocate) {
  Feed run;
  run.feed(800);
  msg::Sample s = run.sample;
  test::AllocationScope scope;
  for (int k = 0; k < 200; ++k) {
    run.stream.next(s.u.data(), s.y.data());
    s.seq = ++run.seq;
    run.send(s);
  }
  EXPECT_EQ(scope.count(), 0);
}

}  // namespace
}  // namespace mpm
