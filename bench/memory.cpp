// What is specific to measuring mpmd: finding it, the plant and
// configuration it is given, the samples it is fed over LCM and the figures
// read from it. Starting, notifying, reading /proc and stopping a child are
// generic and live in tests/support/child_process.hpp.
#include "bench/memory.hpp"

#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <random>
#include <sstream>
#include <vector>

#include "tests/support/child_process.hpp"
#include "sim/builtin_plants.hpp"

#ifdef MPM_BENCH_HAVE_TRANSPORT
#include "config/plant_loader.hpp"
#include "core/mimo_model.hpp"
#include "transport/transport.hpp"
#endif

namespace mpm::bench {

namespace fs = std::filesystem;
using namespace test;  // the process plumbing of tests/support/child_process.hpp

std::string own_exe_dir() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string() : exe.parent_path().string();
}

std::optional<std::string> find_mpmd(const std::string& exe_dir, std::string& why) {
  if (const char* forced = std::getenv("MPM_MPMD"); forced != nullptr && *forced != '\0') {
    if (is_executable_file(forced)) return std::string(forced);
    why = std::string("MPM_MPMD=") + forced + " is not an executable file";
    return std::nullopt;
  }
  if (exe_dir.empty()) {
    why = "no mpmd: the folder of this program is unknown (/proc/self/exe unreadable); set MPM_MPMD";
    return std::nullopt;
  }
  for (const std::string& candidate : {exe_dir + "/mpmd", exe_dir + "/mpmd/mpmd"}) {
    if (is_executable_file(candidate)) return candidate;
  }
  why = "no mpmd executable at " + exe_dir + "/mpmd or " + exe_dir +
        "/mpmd/mpmd (built with MPM_BUILD_TRANSPORTS=OFF?); set MPM_MPMD to measure one elsewhere";
  return std::nullopt;
}

std::string bench_plant_yaml(std::size_t n) {
  if (n == 2) return std::string(*sim::builtin_plant_text("wood-berry.yaml"));
  std::ostringstream y;
  y.precision(6);
  y << "# " << n << "x" << n << " benchmark plant written by `mpm bench`: first-order channels with dead time.\n"
    << "plant: bench-" << n << "x" << n << "\nsample_time: 1\ninputs: [";
  for (std::size_t i = 0; i < n; ++i) y << (i ? ", u" : "u") << i + 1;
  y << "]\noutputs: [";
  for (std::size_t j = 0; j < n; ++j) y << (j ? ", y" : "y") << j + 1;
  y << "]\nmodel:\n";
  for (std::size_t j = 0; j < n; ++j) {
    for (std::size_t i = 0; i < n; ++i) {
      // Deterministic spread of poles 0.80..0.95, gains +-(0.2..1.0), delays 1..5.
      const std::size_t k = j * n + i;
      const double pole = 0.80 + 0.15 * static_cast<double>((k * 37) % 101) / 100.0;
      const double gain = (k % 3 == 0 ? -1.0 : 1.0) * (0.2 + 0.8 * static_cast<double>((k * 53) % 97) / 96.0);
      y << "  - {output: y" << j + 1 << ", input: u" << i + 1 << ", num: [" << gain * (1.0 - pole) << "], den: [1, "
        << -pole << "], delay: " << 1 + (i + 2 * j) % 5 << "}\n";
    }
  }
  y << "noise:\n";
  for (std::size_t j = 0; j < n; ++j)
    y << "  - {output: y" << j + 1 << ", num: [1], den: [1, -" << (j % 2 ? 0.9 : 0.8) << "], variance: 1}\n";
  std::string zeros;
  for (std::size_t i = 0; i < n; ++i) zeros += i ? ", 0" : "0";
  y << "operating_point:\n  inputs: [" << zeros << "]\n  outputs: [" << zeros << "]\n";
  return y.str();
}

#ifndef MPM_BENCH_HAVE_TRANSPORT

std::optional<MpmdMemory> measure_mpmd_memory(const MpmdRun&, std::string& why) {
  why = "this mpm was built without the transports (MPM_BUILD_TRANSPORTS=OFF): it cannot feed mpmd samples";
  return std::nullopt;
}

#else

namespace {

using Clock = std::chrono::steady_clock;

// Samples per chunk: each chunk is confirmed by a status before the next is
// sent, so a burst never overruns a socket buffer (UDP would drop silently).
constexpr std::size_t kChunk = 50;
// Longest wait for a chunk's confirmation (at 50x50 a used sample takes ~50 ms).
constexpr std::chrono::seconds kChunkTimeout{60};

// Samples as a controller would publish them for a matched plant:
// y = y0 + G_M (u - u0) + d, u white around u0, d of the plant's first-order
// noise models (white where there is none). A matched plant raises no alarm
// storm that would make mpmd's memory a measure of its logging.
class SampleSource {
 public:
  SampleSource(const PlantModel& plant, const std::string& controller)
      : u0_(plant.n_inputs(), 0.0),
        y0_(plant.n_outputs(), 0.0),
        pole_(plant.n_outputs(), 0.0),
        d_(plant.n_outputs(), 0.0),
        zeros_(plant.n_outputs(), 0.0),
        minus_model_(plant.n_outputs(), 0.0),
        rng_(7) {
    if (plant.operating_point) {
      u0_ = plant.operating_point->inputs;
      y0_ = plant.operating_point->outputs;
    }
    for (std::size_t j = 0; j < plant.n_outputs(); ++j) {
      const auto& n = plant.noise[j];
      if (n && n->tf.den.size() == 2 && n->tf.num.size() == 1) pole_[j] = -n->tf.den[1] / n->tf.den[0];
    }
    model_ = ResidualGenerator(plant, u0_);
    sample_.controller_id = controller;
    sample_.session_id = 1;
    sample_.u.resize(plant.n_inputs());
    sample_.y.resize(plant.n_outputs());
  }
  const msg::Sample& next() {
    for (std::size_t i = 0; i < u0_.size(); ++i) sample_.u[i] = u0_[i] + normal_(rng_);
    model_.step(sample_.u.data(), zeros_.data(), minus_model_.data());  // 0 - G_M (u - u0)
    for (std::size_t j = 0; j < y0_.size(); ++j) {
      d_[j] = pole_[j] * d_[j] + normal_(rng_);  // variance 1, as the plant files say
      sample_.y[j] = y0_[j] - minus_model_[j] + d_[j];
    }
    ++sample_.seq;
    sample_.utime = std::chrono::duration_cast<std::chrono::microseconds>(
                        std::chrono::system_clock::now().time_since_epoch())
                        .count();
    return sample_;
  }

 private:
  std::vector<double> u0_, y0_, pole_, d_, zeros_, minus_model_;
  ResidualGenerator model_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  msg::Sample sample_;
};

std::string tag(std::size_t n) { return std::to_string(n) + "x" + std::to_string(n); }

// A YAML single-quoted scalar: any path, spaces and colons included.
std::string quoted(const std::string& text) {
  std::string q = "'";
  for (const char c : text) q += c == '\'' ? std::string("''") : std::string(1, c);
  return q + "'";
}

std::string daemon_yaml(const std::string& plant_path, const std::string& controller,
                        const transport::LcmSettings& lcm) {
  return "# written by `mpm bench` to measure mpmd's resident memory\n"
         "controller_id: " + controller + "\n"
         "plant: " + quoted(plant_path) + "\n"
         "monitor:            # the orders of the paper, as the other bench figures\n"
         "  ar_order: 20\n"
         "  input_order: 10\n"
         "  forgetting: 0.999\n"
         "  settle_samples: 0 # every sample reaches the monitor\n"
         "transport:\n"
         "  kind: lcm\n"
         "  lcm:\n"
         "    url: \"" + lcm.url + "\"\n"
         "    sample_channel: " + lcm.sample_channel + "\n"
         "    alarm_channel: " + lcm.alarm_channel + "\n"
         "    status_channel: " + lcm.status_channel + "\n"
         "status_period: 0.1  # the status confirms each chunk of samples\n"
         "log_interval: 3600\n";
}

// What the last status of our controller said.
struct Seen {
  std::int64_t seen = -1;
  std::int64_t used = 0;
};

class Measurement {
 public:
  Measurement(const MpmdRun& run, std::string& why) : run_(run), why_(why), child_(run.stop_timeout) {}

  std::optional<MpmdMemory> run() {
    if (!dir_.ok(why_) || !write_files() || !open_transport() || !notify_.bind(dir_.file("notify.sock"), why_))
      return std::nullopt;
    if (!child_.start({run_.mpmd, "--config", dir_.file("mpmd.yaml")},
                      environment_with_notify_socket(dir_.file("notify.sock")), dir_.file("mpmd.log"), why_))
      return std::nullopt;
    MpmdMemory m;
    m.pid = child_.pid();
    m.url = lcm_.url;
    if (!wait_ready()) return std::nullopt;
    // The child's memory now, or the failure said.
    const auto read_memory = [&]() -> std::optional<ProcMemory> {
      std::optional<ProcMemory> now = read_proc_memory(m.pid);
      if (!now) fail("cannot read /proc/" + std::to_string(m.pid) + "/status");
      return now;
    };
    const std::optional<ProcMemory> at_ready = read_memory();
    if (!at_ready) return std::nullopt;
    m.ready_rss_mb = at_ready->vm_rss_mb;
    m.ready_anon_mb = at_ready->rss_anon_mb;
    if (!feed()) return std::nullopt;
    const std::optional<ProcMemory> after = read_memory();
    if (!after) return std::nullopt;
    m.rss_mb = after->vm_rss_mb;
    m.hwm_mb = after->vm_hwm_mb;
    m.anon_mb = after->rss_anon_mb;
    m.file_mb = after->rss_file_mb;
    m.samples_sent = sent_;
    m.samples_seen = static_cast<std::size_t>(seen_.seen);
    m.samples_used = static_cast<std::size_t>(seen_.used);
    child_.stop();
    return m;
  }

 private:
  bool write_files() {
    const std::string plant_text = bench_plant_yaml(run_.n);
    try {
      plant_ = config::parse_plant(plant_text, "bench plant " + tag(run_.n));
    } catch (const std::exception& e) {
      why_ = e.what();
      return false;
    }
    const int pid = static_cast<int>(::getpid());
    controller_ = "bench-" + tag(run_.n);
    // ttl=0 keeps it on this host; a port of our own (not mpmd's default
    // 7667 nor the latency figure's 7671) and channels named after our pid.
    lcm_.url = "udpm://239.255.76.67:" + std::to_string(7767 + pid % 1000) + "?ttl=0";
    lcm_.sample_channel = "MPM_BENCH_SAMPLE_" + std::to_string(pid);
    lcm_.alarm_channel = "MPM_BENCH_ALARM_" + std::to_string(pid);
    lcm_.status_channel = "MPM_BENCH_STATUS_" + std::to_string(pid);
    if (write_text_file(dir_.file("plant.yaml"), plant_text) &&
        write_text_file(dir_.file("mpmd.yaml"), daemon_yaml(dir_.file("plant.yaml"), controller_, lcm_)))
      return true;
    why_ = "cannot write the plant and configuration files to " + dir_.file("");
    return false;
  }

  bool open_transport() {
    transport::Settings s;
    s.kind = transport::Kind::kLcm;
    s.lcm = lcm_;
    transport_ = transport::create(s, why_);
    if (!transport_) return false;
    const bool ok = transport_->subscribe_status([this](const msg::Status& st) {
      if (st.controller_id != controller_) return;
      seen_.seen = st.samples_seen;
      seen_.used = st.samples_used;
    });
    if (!ok) why_ = "cannot subscribe to mpmd's status on " + lcm_.url;
    return ok;
  }

  // Stops mpmd and sets why_ to `what` and mpmd's last log line; false.
  bool fail(const std::string& what) {
    child_.stop();
    why_ = what;
    const std::string last = last_nonempty_line(dir_.file("mpmd.log"));
    if (!last.empty()) why_ += "; mpmd's last log line: " + last;
    return false;
  }

  std::string died() { return "mpmd (" + run_.mpmd + ") " + describe_exit(*child_.exit_status()); }

  bool wait_ready() {
    switch (wait_for_ready(notify_, child_, run_.ready_timeout)) {
      case ReadyWait::kReady:
        return true;
      case ReadyWait::kExited:
        return fail(died() + " before READY=1");
      case ReadyWait::kTimedOut:
        break;
    }
    const double s = std::chrono::duration<double>(run_.ready_timeout).count();
    char text[64];
    std::snprintf(text, sizeof text, " sent no READY=1 within %.0f s", s);
    return fail("mpmd (" + run_.mpmd + ")" + text);
  }

  // Publishes chunks of samples, each confirmed by a status, until the
  // monitor has used run_.used of them.
  bool feed() {
    SampleSource source(plant_, controller_);
    while (seen_.used < static_cast<std::int64_t>(run_.used)) {
      if (sent_ >= run_.max_samples) {
        return fail("after " + std::to_string(sent_) + " samples mpmd's monitor had used " +
                    std::to_string(seen_.used) + ", not " + std::to_string(run_.used));
      }
      // Once samples are used, exactly as many as are still wanted.
      std::size_t chunk = kChunk;
      if (seen_.used > 0) chunk = std::min(chunk, run_.used - static_cast<std::size_t>(seen_.used));
      chunk = std::min(chunk, run_.max_samples - sent_);
      for (std::size_t k = 0; k < chunk; ++k) {
        if (!transport_->publish(source.next())) return fail("could not publish a sample on " + lcm_.url);
      }
      sent_ += chunk;
      if (!wait_seen(sent_)) return false;
    }
    return true;
  }

  bool wait_seen(std::size_t target) {
    const auto deadline = Clock::now() + kChunkTimeout;
    while (seen_.seen < static_cast<std::int64_t>(target)) {
      if (transport_->handle(std::chrono::milliseconds(20)) < 0)
        return fail("the LCM transport of the bench failed on " + lcm_.url);
      if (!child_.running()) return fail(died() + " while processing samples");
      if (Clock::now() >= deadline) {
        return fail("mpmd's status confirmed " + std::to_string(std::max<std::int64_t>(seen_.seen, 0)) + " of " +
                    std::to_string(target) + " samples sent on " + lcm_.url + " (multicast loopback blocked?)");
      }
    }
    return true;
  }

  const MpmdRun& run_;
  std::string& why_;
  // Declared before the socket and the child: removed after they are closed
  // and stopped (members are destroyed in reverse order).
  TempDir dir_{"mpm-bench"};
  NotifySocket notify_;
  std::unique_ptr<transport::Transport> transport_;
  ChildProcess child_;
  PlantModel plant_;
  std::string controller_;
  transport::LcmSettings lcm_;
  Seen seen_;
  std::size_t sent_ = 0;
};

}  // namespace

std::optional<MpmdMemory> measure_mpmd_memory(const MpmdRun& run, std::string& why) {
  return Measurement(run, why).run();
}

#endif

}  // namespace mpm::bench
