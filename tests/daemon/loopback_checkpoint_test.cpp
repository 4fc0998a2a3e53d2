// mpmd killed with SIGKILL in the middle of a run and started again: it
// resumes from its last checkpoint with statistics equal (to 1e-12 relative)
// to those of an uninterrupted monitor fed the same samples up to that
// checkpoint, the raised alarm still raised and said again; fed the rest of
// the stream it ends where an uninterrupted run ends. A changed plant file
// and a damaged checkpoint both start fresh, with a log line saying why.
// Over LCM, as a separate process, in a private network namespace
// (run_isolated.sh); the reference monitor is built in this process from the
// same configuration file (daemon/mpmd/setup.hpp), as mpmd builds its own.
#include <cmath>
#include <csignal>
#include <filesystem>
#include <fstream>

#include "daemon/mpmd/checkpoint.hpp"
#include "daemon/mpmd/setup.hpp"
#include "loopback_fixture.hpp"
#include "status_compare.hpp"

namespace mpm::test {
namespace {

// The monitor mpmd builds from `config`, fed `samples[0, n)` in this process.
msg::Status reference(const std::string& config, const std::vector<msg::Sample>& samples, std::size_t n) {
  std::string error;
  auto loaded = load_config(config, error);
  EXPECT_TRUE(loaded) << error;
  if (!loaded) return {};
  auto service = make_service(*loaded, {}, error);
  EXPECT_TRUE(service) << error;
  if (!service) return {};
  for (std::size_t k = 0; k < n && k < samples.size(); ++k) service->on_sample(samples[k], {});
  msg::Status s;
  service->fill_status(s, 0, 0);
  return s;
}

class CheckpointTest : public LoopbackTest {
 protected:
  // Every test starts with the first mpmd up, checkpointing.
  void SetUp() override {
    LoopbackTest::SetUp();
    if (HasFatalFailure()) return;
    run = open_session(config_with_checkpoint(), "wb", 0, "first");
    ASSERT_TRUE(run.up) << run.log();
  }

  // Publishes `n` samples of `c` (synced), keeping a copy of each in `sent`.
  bool publish(Controller& c, int n, std::vector<msg::Sample>& sent) const {
    return publish_synced(*run.t, *run.obs, c, n, 50, &sent);
  }

  // mpmd.yaml with a checkpoint every 0.1 s; `plant` replaces the Wood-Berry file.
  std::string config_with_checkpoint(const std::string& plant = "") const {
    const std::string path = write_config("mpmd.yaml", "wb");
    std::string text = ChildProcess::read(path);
    if (!plant.empty()) {
      const std::string from = MPM_SOURCE_DIR "/config/wood-berry.yaml";
      text.replace(text.find(from), from.size(), plant);
    }
    dir().write("mpmd.yaml", text + "checkpoint_path: " + dir().file("mpmd.state") + "\ncheckpoint_interval: 0.1\n");
    return path;
  }

  // The samples seen by the last checkpoint on disk (0 when none can be read).
  std::uint64_t checkpointed(const std::string& config) const {
    std::string error, why;
    auto loaded = load_config(config, error);
    if (!loaded) return 0;
    auto service = make_service(*loaded, {}, error);
    if (!service) return 0;
    if (checkpoint::load(*service, loaded->config.checkpoint_path, checkpoint_fingerprint(*loaded), why) !=
        checkpoint::Outcome::kResumed) {
      return 0;
    }
    return service->counters().seen;
  }

  Session run;  // the first mpmd, opened by SetUp
};

// Now, as a status's utime counts: a status made after it comes from a
// process started after the previous one ended.
std::int64_t unix_micros() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}
bool restarted(const msg::Status& s, std::int64_t after) { return s.utime >= after; }

TEST_P(CheckpointTest, SigkillMidRunResumesTheStatisticsAndTheAlarm) {
  Controller c("wb", 21);
  std::vector<msg::Sample> sent;

  // Matched, then G21 x 1.5 until u1 -> y2 is raised and a checkpoint holds it.
  ASSERT_TRUE(publish(c, 600, sent));
  c.stream.set_g21_gain(1.5);
  for (int k = 0; k < 30 && run.obs->alarms().empty(); ++k) ASSERT_TRUE(publish(c, 50, sent));
  ASSERT_TRUE(run.obs->wait_alarms([](const auto& a) { return !a.empty(); }, std::chrono::seconds(10)));
  const auto raised_at = static_cast<std::uint64_t>(run.obs->alarms().front().sample_sequence);
  ASSERT_TRUE(publish(c, 200, sent));
  ASSERT_TRUE(eventually([&] { return checkpointed(run.config) > raised_at; })) << run.mpmd->stderr_text();

  // More samples in flight, then SIGKILL: what came after the last checkpoint is lost.
  for (int k = 0; k < 100; ++k) {
    sent.push_back(c.next());
    ASSERT_TRUE(run.t->publish(c.sample));
  }
  run.mpmd->signal(SIGKILL);
  ASSERT_TRUE(run.mpmd->wait_exit(std::chrono::seconds(10)).has_value());
  const std::int64_t killed = unix_micros();
  const std::uint64_t resumed_at = checkpointed(run.config);
  ASSERT_GT(resumed_at, raised_at);
  const std::size_t alarms_before = run.obs->alarms().size();

  auto second = start_mpmd(run.config, "second");
  ASSERT_TRUE(run.obs->wait_status("wb", [&](const msg::Status& s) { return restarted(s, killed); }))
      << second->stderr_text();
  const msg::Status resumed = *run.obs->status("wb");
  EXPECT_EQ(static_cast<std::uint64_t>(resumed.samples_seen), resumed_at);
  const double at_resume = compare_status(resumed, reference(run.config, sent, resumed_at));
  EXPECT_LE(at_resume, 1e-12);
  EXPECT_EQ(resumed.alarms_raised, 1);
  EXPECT_EQ(count_lines(second->stderr_text(), "resumed from checkpoint"), 1) << second->stderr_text();
  // The raised alarm is said again by the new process.
  ASSERT_TRUE(run.obs->wait_alarms([&](const auto& a) { return a.size() > alarms_before; }, std::chrono::seconds(10)));
  const msg::Alarm again = run.obs->alarms()[alarms_before];
  EXPECT_TRUE(again.raised && again.output == "y2" && again.input == "u1") << again.text;
  EXPECT_NE(again.text.find("still raised"), std::string::npos) << again.text;

  // The controller sends again from the sample after the checkpoint, then
  // new ones: the run ends where an uninterrupted one ends.
  c.seq = static_cast<std::int64_t>(resumed_at);
  c.sent = c.seq;
  for (std::size_t k = resumed_at; k < sent.size(); ++k) {
    ASSERT_TRUE(run.t->publish(sent[k]));
    ++c.seq;
    ++c.sent;
  }
  c.sample = sent.back();
  ASSERT_TRUE(sync(*run.obs, c));
  ASSERT_TRUE(publish(c, 300, sent));
  const msg::Status end = *run.obs->status("wb");
  const double at_end = compare_status(end, reference(run.config, sent, sent.size()));
  EXPECT_LE(at_end, 1e-12);
  std::printf("SIGKILL after %zu samples, checkpoint at %llu: largest relative difference %.3g at resume, "
              "%.3g after %zu samples\n",
              sent.size() - 300, static_cast<unsigned long long>(resumed_at), at_resume, at_end, sent.size());

  // SIGTERM saves the state once more.
  second->signal(SIGTERM);
  EXPECT_EQ(second->wait_exit(std::chrono::seconds(20)), 0);
  EXPECT_EQ(count_lines(second->stderr_text(), "state saved to"), 1) << second->stderr_text();
  EXPECT_EQ(checkpointed(run.config), sent.size());
}

TEST_P(CheckpointTest, AChangedPlantOrADamagedFileStartsFresh) {
  Controller c("wb", 22);
  std::vector<msg::Sample> sent;
  ASSERT_TRUE(publish(c, 300, sent));
  run.mpmd->signal(SIGTERM);
  ASSERT_EQ(run.mpmd->wait_exit(std::chrono::seconds(20)), 0);
  ASSERT_EQ(checkpointed(run.config), 300u);
  std::int64_t stopped = unix_micros();

  // The same plant with G21's gain changed: another model, so a fresh start.
  std::string plant = ChildProcess::read(MPM_SOURCE_DIR "/config/wood-berry.yaml");
  plant.replace(plant.find("num: [0.5786]"), 13, "num: [0.6000]");
  dir().write("changed-plant.yaml", plant);
  config_with_checkpoint(dir().file("changed-plant.yaml"));
  auto second = start_mpmd(run.config, "second");
  ASSERT_TRUE(run.obs->wait_status("wb", [&](const msg::Status& s) { return restarted(s, stopped); }))
      << second->stderr_text();
  EXPECT_EQ(run.obs->status("wb")->samples_seen, 0);
  EXPECT_EQ(count_lines(second->stderr_text(), "written for another plant file"), 1) << second->stderr_text();
  EXPECT_EQ(count_lines(second->stderr_text(), "starting fresh"), 1) << second->stderr_text();
  second->signal(SIGTERM);
  ASSERT_EQ(second->wait_exit(std::chrono::seconds(20)), 0);
  stopped = unix_micros();

  // A truncated checkpoint: refused, fresh start.
  const std::string state = dir().file("mpmd.state");
  std::filesystem::resize_file(state, std::filesystem::file_size(state) / 2);
  auto third = start_mpmd(run.config, "third");
  ASSERT_TRUE(run.obs->wait_status("wb", [&](const msg::Status& s) { return restarted(s, stopped); }))
      << third->stderr_text();
  EXPECT_EQ(run.obs->status("wb")->samples_seen, 0);
  EXPECT_EQ(count_lines(third->stderr_text(), "refused, starting fresh"), 1) << third->stderr_text();
  third->signal(SIGTERM);
  EXPECT_EQ(third->wait_exit(std::chrono::seconds(20)), 0);
}

INSTANTIATE_TEST_SUITE_P(Transports, CheckpointTest, ::testing::Values(transport::Kind::kLcm), kind_name);

}  // namespace
}  // namespace mpm::test
