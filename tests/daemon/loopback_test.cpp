// mpmd end to end over LCM and over DDS, each in its own process, on this
// host's loopback. Run by ctest inside a private network namespace when one
// can be made (run_isolated.sh).
#include <sys/socket.h>
#include <sys/un.h>

#include <cmath>
#include <fstream>
#include <limits>
#include <set>

#include "loopback_fixture.hpp"

namespace mpm::test {
namespace {

bool alarm_is(const msg::Alarm& a, const std::string& controller, const char* output, const char* input,
              bool raised) {
  return a.controller_id == controller && a.output == output && a.input == input && a.raised == raised;
}

TEST_P(LoopbackTest, MismatchRaisesOnlyU1ToY2AndClearsWhenThePlantReturns) {
  Session run = start_session("wb");
  ASSERT_TRUE(run.up) << run.log();
  Controller c("wb", 11);

  // Matched plant: status flows, the monitor gets ready, nothing is raised.
  ASSERT_TRUE(publish_synced(*run.t, *run.obs, c, 1000)) << run.mpmd->stderr_text();
  ASSERT_TRUE(run.obs->wait_status("wb", [](const msg::Status& s) { return s.ready; }));
  EXPECT_TRUE(run.obs->alarms().empty());

  // G21 x 1.2: the alarm of u1 -> y2 within a bounded number of samples.
  c.stream.set_g21_gain(1.2);
  const std::int64_t onset = c.seq;
  for (int k = 0; k < 20 && run.obs->alarms().empty(); ++k) ASSERT_TRUE(publish_synced(*run.t, *run.obs, c, 50));
  ASSERT_TRUE(run.obs->wait_alarms([](const auto& a) { return !a.empty(); }, std::chrono::seconds(10)));
  const msg::Alarm raised = run.obs->alarms().front();
  EXPECT_TRUE(alarm_is(raised, "wb", "y2", "u1", true)) << raised.text;
  EXPECT_LT(raised.sample_sequence - onset, 600);
  // The focused score raises early, on less evidence in the full space: the
  // channel's conditional score names it on its own below `false_alarm`.
  EXPECT_LT(raised.p_value, 1e-3);
  EXPECT_TRUE(run.obs->wait_status("wb", [](const msg::Status& s) { return s.alarms_raised == 1; }));

  if (GetParam() == transport::Kind::kDds) {
    // DDS alarms are transient-local: an operator who starts listening now
    // still gets the alarm raised before.
    ChildProcess late({kMpm, "listen", "--transport", "dds", "--dds-domain", std::to_string(settings().dds.domain),
                       "--dds-config", kLoopbackXml, "--alarms-only", "--count", "1", "--timeout", "30"},
                      dir().file("late.out"), dir().file("late.err"));
    ASSERT_EQ(late.wait_exit(std::chrono::seconds(40)), 0) << late.stderr_text();
    EXPECT_EQ(count_lines(late.stdout_text(), "\"controller\":\"wb\""), 1) << late.stdout_text();
    EXPECT_EQ(count_lines(late.stdout_text(), "\"state\":\"raised\""), 1) << late.stdout_text();
  }

  // Back to the matched plant: it clears; no other channel was ever raised.
  c.stream.set_g21_gain(1.0);
  for (int k = 0; k < 40 && run.obs->alarms().size() < 2; ++k) ASSERT_TRUE(publish_synced(*run.t, *run.obs, c, 50));
  ASSERT_TRUE(run.obs->wait_alarms([](const auto& a) { return a.size() >= 2; }, std::chrono::seconds(10)));
  const auto alarms = run.obs->alarms();
  ASSERT_EQ(alarms.size(), 2u);
  EXPECT_TRUE(alarm_is(alarms[1], "wb", "y2", "u1", false)) << alarms[1].text;
  EXPECT_TRUE(run.obs->wait_status("wb", [](const msg::Status& s) { return s.alarms_raised == 0; }));

  run.mpmd->signal(SIGTERM);
  EXPECT_EQ(run.mpmd->wait_exit(std::chrono::seconds(20)), 0);
  EXPECT_EQ(count_lines(run.mpmd->stderr_text(), "model-plant mismatch on u1 -> y2"), 1);
}

TEST_P(LoopbackTest, BadSamplesAreCountedLoggedOnceAndSurvived) {
  Session run = start_session("wb");
  ASSERT_TRUE(run.up) << run.log();
  Controller c("wb", 12);
  ASSERT_TRUE(publish_synced(*run.t, *run.obs, c, 600));
  ASSERT_TRUE(run.obs->wait_status("wb", [](const msg::Status& s) { return s.ready; }));
  const msg::Status before = *run.obs->status("wb");

  for (int k = 0; k < 3; ++k) {  // wrong-sized: three inputs
    msg::Sample s = c.next();
    s.u.push_back(0.0);
    // Refused by the transport's decoder against the plant's dimensions, so
    // counted as malformed but never seen by the service (not in c.sent).
    ASSERT_TRUE(run.t->publish(s));
  }
  c.seq += 5;  // a gap of five
  ASSERT_TRUE(send(*run.t, c, c.next()));
  ASSERT_TRUE(send(*run.t, c, c.sample));  // duplicated twice
  ASSERT_TRUE(send(*run.t, c, c.sample));
  const msg::Sample skipped = c.next();  // out of order
  ASSERT_TRUE(send(*run.t, c, c.next()));
  ASSERT_TRUE(send(*run.t, c, skipped));
  for (int k = 0; k < 2; ++k) {  // NaN values
    msg::Sample s = c.next();
    s.y[0] = std::numeric_limits<double>::quiet_NaN();
    ASSERT_TRUE(send(*run.t, c, s));
  }
  c.sample.session_id += 1;  // the publisher restarts: new session, from 1
  c.seq = 0;
  ASSERT_TRUE(publish_synced(*run.t, *run.obs, c, 500));

  const msg::Status after = *run.obs->status("wb");
  EXPECT_EQ(after.malformed - before.malformed, 3);
  EXPECT_EQ(after.gaps - before.gaps, 2);  // the planted one and the hole of the late sample
  // The planted five, the three refused samples (their numbers never reached
  // the service) and the hole of the late sample.
  EXPECT_EQ(after.missing - before.missing, 9);
  EXPECT_EQ(after.duplicates - before.duplicates, 2);
  EXPECT_EQ(after.out_of_order - before.out_of_order, 1);
  EXPECT_EQ(after.nan_samples - before.nan_samples, 2);
  EXPECT_EQ(after.restarts - before.restarts, 1);
  // Still monitoring, with the statistics it had.
  EXPECT_TRUE(run.mpmd->running());
  EXPECT_TRUE(after.ready);
  // A restart means an unknown gap: the model settles again and the
  // regressors refill (about 200 samples here), then monitoring goes on.
  EXPECT_GT(after.samples_used, before.samples_used + 200);
  EXPECT_GE(after.effective_samples, 0.9 * before.effective_samples);

  const std::string log = run.mpmd->stderr_text();
  EXPECT_EQ(count_lines(log, "could not be decoded"), 1) << log;
  EXPECT_EQ(count_lines(log, "samples missing"), 1) << log;
  EXPECT_EQ(count_lines(log, "duplicate"), 1) << log;
  EXPECT_EQ(count_lines(log, "arrived after"), 1) << log;
  EXPECT_EQ(count_lines(log, "NaN"), 1) << log;
  EXPECT_EQ(count_lines(log, "publisher restarted"), 1) << log;
}

TEST_P(LoopbackTest, SighupWithABrokenConfigKeepsTheRunningOne) {
  Session run = start_session("wb");
  ASSERT_TRUE(run.up) << run.log();
  Controller c("wb", 13);
  ASSERT_TRUE(publish_synced(*run.t, *run.obs, c, 400));
  const double threshold = run.obs->status("wb")->raise_threshold;

  // Broken: a monitor setting out of range.
  write_config("mpmd.yaml", "wb", "monitor: {forgetting: 1.5}\n");
  run.mpmd->signal(SIGHUP);
  ASSERT_TRUE(eventually([&] { return count_lines(run.mpmd->stderr_text(), "reload failed") == 1; }))
      << run.mpmd->stderr_text();
  EXPECT_NE(run.mpmd->stderr_text().find("forgetting"), std::string::npos) << "the error names the key";
  EXPECT_TRUE(run.mpmd->running());
  ASSERT_TRUE(publish_synced(*run.t, *run.obs, c, 200)) << "still serving";
  EXPECT_EQ(run.obs->status("wb")->raise_threshold, threshold) << "still the old settings";
  EXPECT_GE(run.obs->status("wb")->samples_seen, 600);

  // Not YAML at all.
  dir().write("mpmd.yaml", "controller_id: [unclosed\n");
  run.mpmd->signal(SIGHUP);
  ASSERT_TRUE(eventually([&] { return count_lines(run.mpmd->stderr_text(), "reload failed") == 2; }));
  ASSERT_TRUE(publish_synced(*run.t, *run.obs, c, 100));

  // A valid new level is applied.
  write_config("mpmd.yaml", "wb",
               "monitor: {ar_order: 5, input_order: 10, forgetting: 0.995, false_alarm: 1.0e-3,\n"
               "          false_alarms_per_year: 1000, settle_samples: 100}\n");
  run.mpmd->signal(SIGHUP);
  ASSERT_TRUE(run.obs->wait_status("wb", [&](const msg::Status& s) { return s.raise_threshold < threshold; }));
  EXPECT_EQ(count_lines(run.mpmd->stderr_text(), "reloaded"), 1);
  run.mpmd->signal(SIGTERM);
  EXPECT_EQ(run.mpmd->wait_exit(std::chrono::seconds(20)), 0);
}

// The sd_notify protocol, as systemd would see it: a datagram socket named
// by NOTIFY_SOCKET.
class NotifySocket {
 public:
  explicit NotifySocket(const std::string& path) : path_(path) {
    fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    sockaddr_un addr{};
    addr.sun_family = AF_UNIX;
    std::snprintf(addr.sun_path, sizeof addr.sun_path, "%s", path.c_str());
    bound_ = ::bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0;
    timeval tv{0, 100000};
    ::setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  }
  ~NotifySocket() { ::close(fd_); }
  bool bound() const { return bound_; }
  // Collects messages until one contains `needle` or the timeout.
  bool wait_for(const std::string& needle, std::chrono::seconds timeout = std::chrono::seconds(30)) {
    return eventually(
        [&] {
          char buf[512];
          const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
          if (n > 0) messages.emplace_back(buf, static_cast<std::size_t>(n));
          for (const auto& m : messages) {
            if (m.find(needle) != std::string::npos) return true;
          }
          return false;
        },
        timeout);
  }
  // Collects messages until `needle` has come at least `n` times.
  bool wait_count(const std::string& needle, int n) {
    return eventually([&] {
      wait_for("never", std::chrono::seconds(0));
      return count(needle) >= n;
    });
  }
  int count(const std::string& needle) const {
    int n = 0;
    for (const auto& m : messages) n += m.find(needle) != std::string::npos ? 1 : 0;
    return n;
  }
  std::vector<std::string> messages;

 private:
  std::string path_;
  int fd_ = -1;
  bool bound_ = false;
};

TEST_P(LoopbackTest, TellsSystemdReadyWatchdogReloadingAndStopping) {
  auto t = make_transport();
  ASSERT_TRUE(t);
  Observer obs(*t);
  NotifySocket notify(dir().file("notify.sock"));
  ASSERT_TRUE(notify.bound());
  const std::string config = write_config("mpmd.yaml", "wb");
  auto mpmd = start_mpmd(config, "mpmd", {{"NOTIFY_SOCKET", dir().file("notify.sock")}, {"WATCHDOG_USEC", "400000"}});
  ASSERT_TRUE(notify.wait_for("READY=1")) << mpmd->stderr_text();
  EXPECT_NE(notify.messages.front().find("STATUS=watching controller 'wb'"), std::string::npos);
  ASSERT_TRUE(notify.wait_for("WATCHDOG=1"));
  ASSERT_TRUE(notify.wait_count("WATCHDOG=1", 3)) << "the watchdog keeps being fed";
  mpmd->signal(SIGHUP);
  ASSERT_TRUE(notify.wait_for("RELOADING=1"));
  ASSERT_TRUE(notify.wait_count("READY=1", 2)) << "READY=1 again after the reload";
  mpmd->signal(SIGTERM);
  ASSERT_TRUE(notify.wait_for("STOPPING=1"));
  EXPECT_EQ(mpmd->wait_exit(std::chrono::seconds(20)), 0);
}

// Three controllers, one mpmd each, one domain / multicast group; one
// `mpm listen` sees every monitor's status and alarms.
TEST_P(LoopbackTest, ThreeControllersOneListener) {
  auto t = make_transport();
  ASSERT_TRUE(t);
  Observer obs(*t);
  const std::vector<std::string> ids{"column-a", "column-b", "column-c"};
  std::vector<std::unique_ptr<ChildProcess>> daemons;
  for (const auto& id : ids) daemons.push_back(start_mpmd(write_config(id + ".yaml", id), id));
  for (const auto& id : ids) {
    ASSERT_TRUE(obs.wait_status(id, [](const msg::Status&) { return true; }, kStartTimeout)) << id;
  }
  ASSERT_TRUE(t->wait_for_sample_readers(3, kStartTimeout));

  std::vector<std::string> listen_args{kMpm, "listen", "--transport", transport::to_string(settings().kind),
                                       "--lcm-url", settings().lcm.url, "--dds-domain",
                                       std::to_string(settings().dds.domain), "--dds-config", kLoopbackXml,
                                       "--timeout", "55"};
  ChildProcess listener(listen_args, dir().file("listen.out"), dir().file("listen.err"));
  // Subscribed once it prints every monitor's status.
  ASSERT_TRUE(eventually([&] {
    const std::string out = listener.stdout_text();
    for (const auto& id : ids) {
      if (count_lines(out, "\"type\":\"status\",\"controller\":\"" + id + "\"") == 0) return false;
    }
    return true;
  })) << listener.stderr_text();

  std::vector<Controller> controllers;
  for (std::size_t i = 0; i < ids.size(); ++i) controllers.emplace_back(ids[i], 20 + i);
  auto round = [&](int n) {
    for (int k = 0; k < n; ++k) {
      for (auto& c : controllers) {
        if (!t->publish(c.next())) return false;
        ++c.sent;
      }
      if ((k + 1) % 50 == 0) {
        for (auto& c : controllers) {
          if (!sync(obs, c)) return false;
        }
      }
    }
    return true;
  };
  ASSERT_TRUE(round(800));
  // Column b's plant drifts; the others stay matched.
  controllers[1].stream.set_g21_gain(1.3);
  for (int k = 0; k < 20 && obs.alarms().empty(); ++k) ASSERT_TRUE(round(50));
  ASSERT_TRUE(obs.wait_alarms([](const auto& a) { return !a.empty(); }, std::chrono::seconds(10)));
  EXPECT_TRUE(alarm_is(obs.alarms().front(), "column-b", "y2", "u1", true));

  // The listener printed that alarm, once, with its controller.
  ASSERT_TRUE(eventually([&] { return count_lines(listener.stdout_text(), "\"type\":\"alarm\"") >= 1; }));
  const std::string out = listener.stdout_text();
  EXPECT_EQ(count_lines(out, "\"type\":\"alarm\",\"controller\":\"column-b\""), 1) << out;
  EXPECT_EQ(count_lines(out, "\"type\":\"alarm\""), 1);
  EXPECT_EQ(count_lines(out, "\"state\":\"raised\""), 1);
  for (const auto& id : ids) {
    EXPECT_TRUE(obs.status(id)->ready) << id;
    EXPECT_EQ(obs.status(id)->gaps, 0) << id;
    EXPECT_EQ(obs.status(id)->malformed, 0) << id;
    EXPECT_EQ(obs.status(id)->restarts, 0) << id;
  }
  EXPECT_EQ(obs.status("column-a")->alarms_raised, 0);
  EXPECT_EQ(obs.status("column-c")->alarms_raised, 0);
  listener.signal(SIGTERM);
  EXPECT_EQ(listener.wait_exit(std::chrono::seconds(10)), 0);
  for (auto& d : daemons) {
    d->signal(SIGTERM);
    EXPECT_EQ(d->wait_exit(std::chrono::seconds(20)), 0);
  }
}

// `mpm replay` publishes a recording as the controller would.
TEST_P(LoopbackTest, ReplayCommandPublishesARecording) {
  Session run = start_session("wb", 0);
  ASSERT_TRUE(run.up) << run.log();
  // A recording in the CSV layout of formats.md, with a setpoint and an extra signal.
  {
    std::ofstream csv(dir().file("run.csv"));
    csv << "t,u1,u2,y1,y2,r_y1,feed_flow\n";
    WoodBerryStream stream(5);
    for (int k = 0; k < 500; ++k) {
      double u[2], y[2];
      stream.next(u, y);
      csv << k << ',' << u[0] << ',' << u[1] << ',' << y[0] << ',' << y[1] << ",90,1.5\n";
    }
  }
  ChildProcess replay({kMpm, "replay", "--config", run.config, "--data", dir().file("run.csv"), "--rate", "2000"},
                      dir().file("replay.out"), dir().file("replay.err"));
  ASSERT_EQ(replay.wait_exit(std::chrono::seconds(40)), 0) << replay.stderr_text();
  EXPECT_NE(replay.stdout_text().find("published 500 samples"), std::string::npos) << replay.stdout_text();
  ASSERT_TRUE(run.obs->wait_status("wb", [](const msg::Status& s) { return s.samples_seen == 500; }))
      << run.obs->status("wb")->samples_seen;
  const msg::Status s = *run.obs->status("wb");
  EXPECT_EQ(s.malformed, 0);
  EXPECT_EQ(s.restarts, 0);
  EXPECT_GT(s.samples_used, 200);  // all but the settle time and regressor fill
}

// `mpm simulate-live` with `scenario_args` runs a closed loop on Wood-Berry
// and publishes 300 samples as the MPC would; mpmd sees every one, clean.
class SimulateLiveTest : public LoopbackTest {
 protected:
  void expect_simulate_live_drives_mpmd(const std::vector<std::string>& scenario_args) {
    Session run = start_session("wood-berry", 0);
    ASSERT_TRUE(run.up) << run.log();
    std::vector<std::string> args{kMpm, "simulate-live"};
    args.insert(args.end(), scenario_args.begin(), scenario_args.end());
    args.insert(args.end(), {"--config", run.config, "--samples", "300", "--rate", "2000"});
    ChildProcess live(args, dir().file("live.out"), dir().file("live.err"));
    ASSERT_EQ(live.wait_exit(std::chrono::seconds(40)), 0) << live.stderr_text();
    EXPECT_NE(live.stdout_text().find("published 300 samples of " + scenario_args[1]), std::string::npos)
        << live.stdout_text();
    ASSERT_TRUE(run.obs->wait_status("wood-berry", [](const msg::Status& s) { return s.samples_seen == 300; }))
        << run.obs->status("wood-berry")->samples_seen;
    const msg::Status s = *run.obs->status("wood-berry");
    EXPECT_EQ(s.malformed, 0);
    EXPECT_EQ(s.gaps, 0);
    EXPECT_EQ(s.nan_samples, 0);
  }
};

TEST_P(SimulateLiveTest, PublishesTheClosedLoop) {
  expect_simulate_live_drives_mpmd({"--scenario", "wood-berry-nominal"});
}

// The loop tuned from a plant file (plant-nominal) drives mpmd the same way:
// simulate-live takes the tuned loop, not a fixed default.
TEST_P(SimulateLiveTest, PublishesTheLoopTunedFromThePlantFile) {
  expect_simulate_live_drives_mpmd({"--scenario", "plant-nominal", "--plant", MPM_SOURCE_DIR "/config/wood-berry.yaml"});
}

INSTANTIATE_TEST_SUITE_P(Transports, LoopbackTest, ::testing::Values(transport::Kind::kLcm, transport::Kind::kDds),
                         kind_name);
INSTANTIATE_TEST_SUITE_P(Transports, SimulateLiveTest, ::testing::Values(transport::Kind::kLcm, transport::Kind::kDds),
                         kind_name);

}  // namespace
}  // namespace mpm::test
