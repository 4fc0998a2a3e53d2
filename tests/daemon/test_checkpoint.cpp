// The checkpoint of MonitorService: a service restored from it continues
// exactly as the one that wrote it (every statistic, counter and alarm), and
// a file that is truncated, corrupt, of another format or of another setup is
// refused with a reason, never trusted.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include "config/daemon_config.hpp"
#include "daemon/mpmd/checkpoint.hpp"
#include "service_fixture.hpp"
#include "status_compare.hpp"
#include "child_process.hpp"
#include "wood_berry_stream.hpp"

namespace mpm {
namespace {

constexpr std::uint64_t kFingerprint = 0x1234abcdull;

// The Wood-Berry stream with G21 x 1.3 from sample `onset` on: the alarm of
// u1 -> y2 is raised before the stream's middle.
std::vector<msg::Sample> stream(int n, int onset = 700, std::uint64_t seed = 5) {
  test::WoodBerryStream wb(seed);
  std::vector<msg::Sample> out(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) {
    if (k == onset) wb.set_g21_gain(1.3);
    msg::Sample& s = out[static_cast<std::size_t>(k)];
    s.controller_id = "wb";
    s.session_id = 9;
    s.seq = k + 1;
    wb.next(s);
  }
  return out;
}

struct Service {
  explicit Service(const PlantModel& plant, ServiceSettings settings = test::fast_service())
      : service(plant, settings, [this](const msg::Alarm& a) { alarms.push_back(a); }) {}
  void feed(const std::vector<msg::Sample>& samples, std::size_t from, std::size_t to) {
    for (std::size_t k = from; k < to; ++k) service.on_sample(samples[k], {});
  }
  void feed(const std::vector<msg::Sample>& samples) { feed(samples, 0, samples.size()); }
  std::vector<unsigned char> encoded() { return checkpoint::encode(service, kFingerprint); }
  msg::Status status() const {
    msg::Status s;
    service.fill_status(s, 0, 0);
    return s;
  }
  std::vector<msg::Alarm> alarms;
  MonitorService service;
};

// compare_status plus what only a resume in this process keeps equal: the
// gap counters, the p-values and the divergence flags.
double compare(const msg::Status& a, const msg::Status& b) {
  EXPECT_EQ(a.gaps, b.gaps);
  EXPECT_EQ(a.missing, b.missing);
  double worst = test::compare_status(a, b);
  for (std::size_t c = 0; c < std::min(a.channels.size(), b.channels.size()); ++c)
    worst = std::max(worst, test::rel(a.channels[c].p_value, b.channels[c].p_value));
  for (std::size_t j = 0; j < std::min(a.loops.size(), b.loops.size()); ++j)
    EXPECT_EQ(a.loops[j].diverging, b.loops[j].diverging) << j;
  return worst;
}

void expect_resumes_exactly(const PlantModel& plant) {
  const auto samples = stream(3000);
  constexpr std::size_t kCut = 1700;
  Service whole(plant);
  whole.feed(samples);
  ASSERT_FALSE(whole.alarms.empty()) << "the planted mismatch must raise before the cut";

  Service first(plant);
  first.feed(samples, 0, kCut);
  ASSERT_TRUE(first.status().alarms_raised > 0);
  const auto bytes = first.encoded();

  Service resumed(plant);
  std::string why;
  ASSERT_EQ(checkpoint::decode(resumed.service, bytes, kFingerprint, why), checkpoint::Outcome::kResumed) << why;
  EXPECT_EQ(compare(resumed.status(), first.status()), 0.0);
  // Raised alarms are still raised and said again.
  resumed.service.republish_raised("test");
  ASSERT_EQ(resumed.alarms.size(), static_cast<std::size_t>(first.status().alarms_raised));
  EXPECT_TRUE(resumed.alarms[0].raised);
  EXPECT_NE(resumed.alarms[0].text.find("still raised"), std::string::npos) << resumed.alarms[0].text;
  resumed.alarms.clear();

  // The rest of the stream: the same statistics and the same alarm edges as
  // the uninterrupted run.
  resumed.feed(samples, kCut, samples.size());
  const double worst = compare(resumed.status(), whole.status());
  EXPECT_LE(worst, 1e-12);
  std::printf("checkpoint resume: largest relative difference of any statistic %.3g\n", worst);
  std::vector<msg::Alarm> after;
  for (const auto& a : whole.alarms) {
    if (a.sample_sequence > static_cast<std::int64_t>(kCut)) after.push_back(a);
  }
  ASSERT_EQ(resumed.alarms.size(), after.size());
  for (std::size_t k = 0; k < after.size(); ++k) {
    EXPECT_EQ(resumed.alarms[k].sample_sequence, after[k].sample_sequence);
    EXPECT_EQ(resumed.alarms[k].raised, after[k].raised);
    EXPECT_EQ(resumed.alarms[k].output, after[k].output);
    EXPECT_EQ(resumed.alarms[k].input, after[k].input);
  }
}

TEST(Checkpoint, ResumedServiceContinuesExactlyAsTheUninterruptedOne) {
  expect_resumes_exactly(test::wood_berry_plant());
}

TEST(Checkpoint, ResumesTheResidualModelMadeFromTheFirstSample) {
  PlantModel plant = test::wood_berry_plant();
  plant.operating_point.reset();  // u0 = the first complete sample, made at run time
  expect_resumes_exactly(plant);
}

// The checkpoint of a service with the default settings fed stream(n).
std::vector<unsigned char> checkpoint_after(const PlantModel& plant, int n) {
  Service source(plant);
  source.feed(stream(n));
  return source.encoded();
}

TEST(Checkpoint, DamagedFilesAreRefusedWithAReason) {
  const PlantModel plant = test::wood_berry_plant();
  const auto good = checkpoint_after(plant, 600);
  std::string why;

  const auto refused = [&](std::vector<unsigned char> bytes, const std::string& reason) {
    Service target(plant);
    why.clear();
    const auto outcome = checkpoint::decode(target.service, bytes, kFingerprint, why);
    EXPECT_EQ(outcome, checkpoint::Outcome::kRefused) << reason;
    EXPECT_NE(why.find(reason), std::string::npos) << why;
  };
  auto truncated = good;
  truncated.resize(good.size() - 8);
  refused(truncated, "truncated");
  refused({good.begin(), good.begin() + 20}, "shorter than its header");
  auto flipped = good;
  flipped[good.size() / 2] ^= 0x10;
  refused(flipped, "checksum");
  auto version = good;
  version[8] += 1;
  refused(version, "format version");
  auto magic = good;
  magic[0] = 'X';
  refused(magic, "not an mpmd checkpoint");

  // Another setup's state under this setup's fingerprint (a forged or stale
  // fingerprint): the sizes give it away.
  ServiceSettings other = test::fast_service();
  other.monitor.ar_order = 6;
  Service wider(plant, other);
  wider.feed(stream(300));
  refused(wider.encoded(), "does not fit this monitor");

  // Another fingerprint: not damaged, just not ours.
  Service target(plant);
  EXPECT_EQ(checkpoint::decode(target.service, good, kFingerprint + 1, why), checkpoint::Outcome::kOtherSetup);
  EXPECT_NE(why.find("another plant"), std::string::npos) << why;
}

// Every truncation and many single-byte changes: refused, never a crash
// (the suite runs this under ASan and UBSan too).
TEST(Checkpoint, NoDamageIsTrusted) {
  const PlantModel plant = test::wood_berry_plant();
  const auto good = checkpoint_after(plant, 300);
  Service target(plant);
  std::string why;
  std::mt19937_64 rng(3);
  int refused = 0, tries = 0;
  for (std::size_t n = 0; n < good.size(); n += 1 + good.size() / 400) {
    ++tries;
    refused += checkpoint::decode(target.service, {good.begin(), good.begin() + static_cast<long>(n)}, kFingerprint,
                                  why) == checkpoint::Outcome::kRefused;
  }
  for (int k = 0; k < 400; ++k) {
    auto bytes = good;
    const std::size_t at = rng() % bytes.size();
    bytes[at] = static_cast<unsigned char>(bytes[at] ^ (1u + rng() % 255u));
    ++tries;
    const auto outcome = checkpoint::decode(target.service, bytes, kFingerprint, why);
    // A changed fingerprint field reads as another setup; everything else is refused.
    refused += outcome == checkpoint::Outcome::kRefused || (outcome == checkpoint::Outcome::kOtherSetup && at >= 16 && at < 24);
  }
  EXPECT_EQ(refused, tries);
}

TEST(Checkpoint, WrittenAtomicallyAndReadBack) {
  test::TempDir dir;
  const std::string path = dir.file("mpmd.state");
  const PlantModel plant = test::wood_berry_plant();
  const auto samples = stream(300);
  Service source(plant);
  source.feed(samples);
  std::string error;
  ASSERT_TRUE(checkpoint::write_atomically(path, source.encoded(), error)) << error;
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
  EXPECT_EQ(std::filesystem::status(path).permissions() & std::filesystem::perms::others_all,
            std::filesystem::perms::none);
  Service target(plant);
  std::string why;
  ASSERT_EQ(checkpoint::load(target.service, path, kFingerprint, why), checkpoint::Outcome::kResumed) << why;
  EXPECT_EQ(compare(target.status(), source.status()), 0.0);
  EXPECT_EQ(checkpoint::load(target.service, dir.file("none"), kFingerprint, why), checkpoint::Outcome::kAbsent);
  // A folder that does not exist: an error naming the path, nothing written.
  EXPECT_FALSE(checkpoint::write_atomically(dir.file("no/such/folder/state"), {1, 2, 3}, error));
  EXPECT_NE(error.find("no/such/folder"), std::string::npos) << error;
}

// The keys: the path relative to the configuration's folder, the interval's
// range with a located error, and the diagnosis window's.
TEST(Checkpoint, ConfigurationKeys) {
  const std::string base = "controller_id: wb\nplant: wood-berry.yaml\n";
  const auto none = config::parse_daemon_config(base, "mpmd.yaml", MPM_SOURCE_DIR "/config");
  EXPECT_EQ(none.checkpoint_path, "");
  EXPECT_EQ(none.checkpoint_interval, 60.0);
  EXPECT_EQ(none.diagnosis_window, 3000);
  const auto set = config::parse_daemon_config(base + "checkpoint_path: state/mpmd.state\ncheckpoint_interval: 5\n"
                                               "diagnosis_window: 0\n",
                                               "mpmd.yaml", MPM_SOURCE_DIR "/config");
  EXPECT_EQ(set.checkpoint_path, MPM_SOURCE_DIR "/config/state/mpmd.state");
  EXPECT_EQ(set.checkpoint_interval, 5.0);
  EXPECT_EQ(set.diagnosis_window, 0);
  const auto error_of = [&](const std::string& extra) {
    try {
      config::parse_daemon_config(base + extra, "mpmd.yaml", MPM_SOURCE_DIR "/config");
    } catch (const config::ConfigError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error_of("checkpoint_interval: 0\n").find("mpmd.yaml:3"), std::string::npos);
  EXPECT_NE(error_of("checkpoint_interval: 0\n").find("checkpoint_interval must be in [0.05, 86400]"), std::string::npos);
  EXPECT_NE(error_of("diagnosis_window: 50\n").find("diagnosis_window must be 0 or a whole number in [200, 1000000]"), std::string::npos);
}

}  // namespace
}  // namespace mpm
