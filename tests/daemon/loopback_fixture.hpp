// Loopback tests of mpmd as a separate process: the test publishes samples as
// a controller would and watches alarms and status as an operator would, over
// real LCM (UDP multicast on loopback) or Cyclone DDS (loopback config).
// Each test gets its own LCM port / DDS domain, so tests never hear each
// other even when not isolated in a network namespace.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <memory>
#include <ostream>
#include <string>

#include "child_process.hpp"
#include "observer.hpp"
#include "transport/transport.hpp"
#include "wood_berry_stream.hpp"

namespace mpm::transport {
// Test names and messages say "lcm" / "dds" instead of the enum's bytes.
inline void PrintTo(Kind kind, std::ostream* os) { *os << to_string(kind); }
}  // namespace mpm::transport

namespace mpm::test {

inline const std::string kMpmd = MPM_BINARY_DIR "/daemon/mpmd/mpmd";
inline const std::string kMpm = MPM_BINARY_DIR "/daemon/mpm";
inline const std::string kLoopbackXml = MPM_SOURCE_DIR "/deploy/dds/cyclonedds-loopback.xml";
// How long a daemon may take to say its first status (and DDS to match readers).
inline constexpr std::chrono::seconds kStartTimeout{30};
// DDS keep-last depth of the tests' sample writers and readers. `mpm replay`
// and `simulate-live` publish up to 500 samples at 2000-3000 per second, and
// a sanitized mpmd on a loaded machine can fall more than the default 64
// (32 ms) behind: keep-last then drops samples by design (never blocking the
// controller; they show up as gaps). A depth above any test's record makes
// reliable delivery complete, so "mpmd saw every sample" is deterministic.
inline constexpr int kSampleHistory = 1024;

// One publishing controller: the Wood-Berry stream with sequence numbers.
struct Controller {
  Controller(std::string id_, std::uint64_t seed) : id(std::move(id_)), stream(seed) {
    sample.controller_id = id;
    sample.session_id = static_cast<std::int64_t>(seed) * 1000 + 1;
  }
  // The next sample (not sent).
  msg::Sample& next() {
    stream.next(sample);
    sample.sim_y.clear();
    sample.seq = ++seq;
    return sample;
  }
  std::string id;
  WoodBerryStream stream;
  msg::Sample sample;
  std::int64_t seq = 0;
  std::int64_t sent = 0;  // messages of this controller put on the wire
};

class LoopbackTest : public ::testing::TestWithParam<transport::Kind> {
 protected:
  void SetUp() override {
    static int counter = 0;
    const int slot = static_cast<int>((::getpid() + counter++ * 7) % 200);
    settings_.kind = GetParam();
    settings_.lcm.url = "udpm://239.255.76.67:" + std::to_string(20000 + slot * 7) + "?ttl=0";
    settings_.dds.domain = 1 + slot;
    settings_.dds.config = kLoopbackXml;
    settings_.dds.sample_history = kSampleHistory;
    ASSERT_FALSE(dir_.path().empty());
  }

  const transport::Settings& settings() const { return settings_; }
  const TempDir& dir() const { return dir_; }

  std::string monitor_yaml() const {
    return "monitor: {ar_order: 5, input_order: 10, forgetting: 0.995, false_alarm: 1.0e-5,\n"
           "          settle_samples: 100}\n";
  }
  std::string transport_yaml() const {
    return std::string("transport:\n  kind: ") + transport::to_string(settings_.kind) + "\n" +
           "  lcm: {url: \"" + settings_.lcm.url + "\"}\n" +
           "  dds: {domain: " + std::to_string(settings_.dds.domain) + ", config: " + kLoopbackXml +
           ", sample_history: " + std::to_string(settings_.dds.sample_history) + "}\n";
  }
  // An mpmd.yaml for `controller`, written to the test's directory.
  std::string write_config(const std::string& name, const std::string& controller,
                           const std::string& monitor = "") const {
    dir_.write(name, "controller_id: " + controller + "\nplant: " MPM_SOURCE_DIR "/config/wood-berry.yaml\n" +
                         (monitor.empty() ? monitor_yaml() : monitor) + transport_yaml() +
                         "status_period: 0.05\nlog_interval: 3600\n");
    return dir_.file(name);
  }

  std::unique_ptr<ChildProcess> start_mpmd(const std::string& config, const std::string& tag = "mpmd",
                                           std::map<std::string, std::string> env = {}) const {
    auto p = std::make_unique<ChildProcess>(std::vector<std::string>{kMpmd, "--config", config},
                                            dir_.file(tag + ".out"), dir_.file(tag + ".err"), std::move(env));
    EXPECT_TRUE(p->started());
    return p;
  }

  std::unique_ptr<transport::Transport> make_transport() const {
    std::string error;
    auto t = transport::create(settings_, error);
    EXPECT_TRUE(t) << error;
    return t;
  }

  // One test's bus and daemon: the test's own transport, an observer on it,
  // and mpmd (its output files named by `tag`) watching `controller` from
  // `config`. `up` once the daemon's first status arrived and (DDS) `readers`
  // sample readers matched ours.
  struct Session {
    std::string config;
    std::unique_ptr<transport::Transport> t;
    std::unique_ptr<Observer> obs;
    std::unique_ptr<ChildProcess> mpmd;
    bool up = false;
    std::string log() const { return mpmd ? mpmd->stderr_text() : "no transport"; }
  };
  Session open_session(const std::string& config, const std::string& controller, int readers,
                       const std::string& tag = "mpmd") const {
    Session s;
    s.config = config;
    s.t = make_transport();
    if (!s.t) return s;
    s.obs = std::make_unique<Observer>(*s.t);
    s.mpmd = start_mpmd(s.config, tag);
    s.up = s.obs->wait_status(controller, [](const msg::Status&) { return true; }, kStartTimeout) &&
           s.t->wait_for_sample_readers(readers, kStartTimeout);
    return s;
  }
  // The same with `mpmd.yaml` of write_config.
  Session start_session(const std::string& controller, int readers = 1) const {
    return open_session(write_config("mpmd.yaml", controller), controller, readers);
  }

  // Publishes `n` samples, `chunk` at a time, after each chunk waiting until
  // the daemon's status shows it has seen them: no sample is lost to a full
  // socket buffer on a slow machine, and the test never sleeps blindly.
  // With a `log`, a copy of each sample is appended to it.
  static bool publish_synced(transport::Transport& t, Observer& obs, Controller& c, int n, int chunk = 50,
                             std::vector<msg::Sample>* log = nullptr) {
    for (int k = 0; k < n; ++k) {
      const msg::Sample& sample = c.next();
      if (log != nullptr) log->push_back(sample);
      if (!t.publish(sample)) return false;
      ++c.sent;
      if ((k + 1) % chunk == 0 || k + 1 == n) {
        if (!sync(obs, c)) return false;
      }
    }
    return true;
  }
  static bool send(transport::Transport& t, Controller& c, const msg::Sample& s) {
    ++c.sent;
    return t.publish(s);
  }
  static bool sync(Observer& obs, const Controller& c) {
    const std::int64_t sent = c.sent;
    return obs.wait_status(c.id, [sent](const msg::Status& s) { return s.samples_seen >= sent; });
  }

 private:
  transport::Settings settings_;
  TempDir dir_;
};

inline std::string kind_name(const ::testing::TestParamInfo<transport::Kind>& info) {
  return info.param == transport::Kind::kLcm ? "Lcm" : "Dds";
}

}  // namespace mpm::test
