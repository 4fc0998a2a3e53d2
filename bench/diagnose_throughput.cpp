#include "bench/diagnose_throughput.hpp"

#include <spawn.h>
#include <sys/wait.h>
#include <time.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <thread>
#include <utility>
#include <vector>

#include "tests/support/child_process.hpp"
#include "config/plant_loader.hpp"
#include "core/diagnosis.hpp"
#include "core/granger_monitor.hpp"
#include "daemon/offline.hpp"
#include "sim/builtin_plants.hpp"
#include "sim/closed_loop.hpp"
#include "sim/scenarios.hpp"

namespace mpm::bench {
namespace {

namespace fs = std::filesystem;
using test::describe_exit;
using test::read_proc_memory;

constexpr const char* kScenario = "wood-berry-g21-gain";

// A fresh folder from mkdtemp, removed with everything in it on destruction.
class ScratchDir {
 public:
  ScratchDir() {
    std::error_code ec;
    const fs::path base = fs::temp_directory_path(ec);
    std::string pattern = ((ec ? fs::path("/tmp") : base) / "mpm-bench-diagnose-XXXXXX").string();
    if (::mkdtemp(pattern.data()) == nullptr)
      throw std::runtime_error("mkdtemp(" + pattern + ") failed: " + std::strerror(errno));
    path_ = pattern;
  }
  ~ScratchDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  std::string file(const char* name) const { return (path_ / name).string(); }

 private:
  fs::path path_;
};

double process_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// `mpm diagnose --quiet --plant PLANT --data DATA` up to the report: what the
// command does before it formats the JSON (not timed: a few kB of text), by
// the command's own pipeline (daemon/offline.hpp).
diagnosis::Result diagnose_files(const std::string& plant_path, const std::string& data_path, std::size_t& threads) {
  const PlantModel plant = config::load_plant(plant_path);
  threads = replay_threads(plant.n_outputs());
  return diagnose_record(plant, config::load_recording(data_path), {}).result;
}

extern "C" char** environ;

// Runs `exe diagnose --quiet --plant PLANT --data DATA --json OUT` as a child
// and returns its peak resident set in MB, or nullopt with `why`. The peak is
// the child's VmHWM read from /proc every 10 ms until it exits (wait4's
// ru_maxrss would not do: it keeps the larger of the child's peak and this
// process's resident set when the child was spawned).
std::optional<double> child_peak_rss_mb(const std::string& exe, const std::string& plant_path,
                                        const std::string& data_path, const std::string& out_path,
                                        std::string& why) {
  std::vector<std::string> args{exe, "diagnose", "--quiet", "--plant", plant_path, "--data", data_path,
                                "--json", out_path};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  if (const int e = posix_spawn(&pid, exe.c_str(), nullptr, nullptr, argv.data(), environ); e != 0) {
    why = "cannot start " + exe + ": " + std::strerror(e);
    return std::nullopt;
  }
  int status = 0;
  double peak = 0.0;
  for (;;) {
    if (const auto m = read_proc_memory(pid)) peak = std::max(peak, m->vm_hwm_mb);
    const pid_t got = ::waitpid(pid, &status, WNOHANG);
    if (got == pid) break;
    if (got < 0 && errno != EINTR) {
      why = std::string("waitpid failed: ") + std::strerror(errno);
      return std::nullopt;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    why = exe + " diagnose " + describe_exit(status) + " on the benchmark recording";
    return std::nullopt;
  }
  return peak;
}

std::size_t index_of(const std::vector<std::string>& names, const std::string& name) {
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end())
    throw std::runtime_error("scenario " + std::string(kScenario) + " edits unknown signal " + name);
  return static_cast<std::size_t>(it - names.begin());
}

bool names_channel(const diagnosis::Result& r, std::size_t output, std::size_t input) {
  for (const auto& f : r.findings)
    for (const auto& c : f.channels)
      if (c.output == output && c.input && *c.input == input) return true;
  return false;
}

}  // namespace

std::optional<DiagnoseThroughput> measure_diagnose(std::size_t samples, std::size_t repeats, std::string& why) {
  try {
    const sim::Scenario* scenario = sim::find_scenario(kScenario);
    if (!scenario) throw std::runtime_error(std::string("no scenario ") + kScenario);
    // The shipped plant file, as built into the binary: the same text whether
    // or not a source tree or an installed share/ is around.
    const auto plant_text = sim::builtin_plant_text(scenario->plant_file);
    if (!plant_text) throw std::runtime_error("no built-in " + scenario->plant_file);
    const PlantModel model = config::parse_plant(std::string(*plant_text), scenario->plant_file + " (built in)");

    DiagnoseThroughput r;
    r.scenario = scenario->name;
    r.samples = samples;
    r.repeats = std::max<std::size_t>(1, repeats);
    std::vector<std::pair<std::size_t, std::size_t>> planted;  // (output, input)
    for (const auto& e : scenario->loop.plant.channels) {
      planted.emplace_back(index_of(model.outputs, e.output), index_of(model.inputs, e.input));
      r.planted += (r.planted.empty() ? "" : ", ") + e.output + " <- " + e.input;
    }
    if (planted.empty()) throw std::runtime_error("scenario " + scenario->name + " plants no channel mismatch");

    const ScratchDir dir;
    const std::string plant_path = dir.file("plant.yaml");
    const std::string data_path = dir.file("run.csv");
    {
      std::ofstream f(plant_path);
      f << *plant_text;
      if (!f) throw std::runtime_error("cannot write " + plant_path);
    }
    {
      sim::ClosedLoop loop(model, scenario->loop, 1);
      config::write_recording(data_path, sim::simulate(loop, samples, data_path));
    }

    struct Run {
      double wall, cpu;
    };
    std::vector<Run> runs;
    r.found_planted = true;
    for (std::size_t k = 0; k < r.repeats; ++k) {
      const double cpu0 = process_cpu_seconds();
      const auto t0 = std::chrono::steady_clock::now();
      const diagnosis::Result result = diagnose_files(plant_path, data_path, r.threads);
      const auto t1 = std::chrono::steady_clock::now();
      runs.push_back({std::chrono::duration<double>(t1 - t0).count(), process_cpu_seconds() - cpu0});
      for (const auto& [j, i] : planted) r.found_planted = r.found_planted && names_channel(result, j, i);
      if (k == 0) {
        for (const auto& f : result.findings) r.findings += (r.findings.empty() ? "" : "; ") + f.summary;
        if (result.findings.empty()) r.findings = "no finding";
      }
    }
    // Peak memory of the command itself: the `mpm` built and installed beside
    // this program (mpm-bench), whose diagnose subcommand is the pipeline
    // timed above.
    std::error_code ec;
    const fs::path self = fs::read_symlink("/proc/self/exe", ec);
    const fs::path mpm = ec ? fs::path() : self.parent_path() / "mpm";
    if (ec || !test::is_executable_file(mpm.string())) {
      r.rss_note = "not measured: no mpm beside this program (" + (ec ? std::string("/proc/self/exe unreadable") : mpm.string()) + ")";
    } else {
      std::string why_rss;
      r.peak_rss_mb = child_peak_rss_mb(mpm.string(), plant_path, data_path, dir.file("report.json"), why_rss);
      r.rss_note = r.peak_rss_mb ? "peak resident set (VmHWM, read every 10 ms) of `" + mpm.string() +
                                       " diagnose --quiet` run as a child on the same files"
                                 : why_rss;
    }
    std::sort(runs.begin(), runs.end(), [](const Run& a, const Run& b) { return a.wall < b.wall; });
    const Run& median = runs[runs.size() / 2];
    r.wall_seconds = median.wall;
    r.cpu_seconds = median.cpu;
    r.samples_per_s = static_cast<double>(samples) / median.wall;
    r.fastest_samples_per_s = static_cast<double>(samples) / runs.front().wall;
    return r;
  } catch (const std::exception& e) {
    why = std::string("diagnose throughput not measured: ") + e.what();
    return std::nullopt;
  }
}

}  // namespace mpm::bench
