// Resident memory of the real mpmd service process. The bench starts the
// mpmd found next to this program (fork/exec, `mpmd --config FILE`) on a
// plant and configuration it writes to a fresh temporary folder, waits for
// its sd_notify READY=1 on a datagram socket of its own (NOTIFY_SOCKET), feeds
// it samples over LCM until its status says it has processed them all, reads
// /proc/<pid>/status and stops it (SIGTERM, then SIGKILL after a grace time).
// Every path out of the measurement, failures included, reaps the child and
// removes the folder.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <cstddef>
#include <optional>
#include <string>

namespace mpm::bench {

// The mpmd to measure: $MPM_MPMD when set (it must be an executable file),
// else `<exe_dir>/mpmd` (installed layout: bin/mpm beside bin/mpmd) or
// `<exe_dir>/mpmd/mpmd` (build tree: daemon/mpm and daemon/mpmd/mpmd).
// nullopt and `why` (naming where it looked) when there is none, e.g. in a
// build with MPM_BUILD_TRANSPORTS=OFF.
std::optional<std::string> find_mpmd(const std::string& exe_dir, std::string& why);

// The folder of the running program (/proc/self/exe), "" if unknown.
std::string own_exe_dir();

// The plant file the measurement monitors: for n = 2 the built-in Wood-Berry
// file; otherwise n inputs and n outputs, every channel first order with a
// dead time of 1..5 samples, every output with an AR(1) noise model (so the
// monitor computes gamma everywhere), operating point at zero.
std::string bench_plant_yaml(std::size_t n);

struct MpmdRun {
  std::string mpmd;          // path of the executable
  std::size_t n = 2;         // n x n plant (see bench_plant_yaml)
  // Samples are published in chunks, each confirmed by mpmd's status, until
  // the status says its monitor used `used` of them in its statistics (the
  // first ones only fill its lags and let its model filters settle), at most
  // `max_samples` in all.
  std::size_t used = 400;
  std::size_t max_samples = 5000;
  std::chrono::milliseconds ready_timeout{60000};  // for READY=1 (setup of a 50x50 takes seconds)
  std::chrono::milliseconds stop_timeout{10000};   // after SIGTERM, before SIGKILL
};

// /proc/<pid>/status fields of mpmd, in MB (1 MB = 2^20 bytes, as the
// other figures), and what it had processed when they were read.
struct MpmdMemory {
  pid_t pid = 0;
  double rss_mb = 0.0;        // VmRSS after the samples
  double hwm_mb = 0.0;        // VmHWM: peak, setup included
  double anon_mb = 0.0;       // RssAnon: heap and stacks (monitor, queue, buffers)
  double file_mb = 0.0;       // RssFile: mapped executable and shared libraries
  double ready_rss_mb = 0.0;  // VmRSS at READY=1, monitor built, before any sample
  double ready_anon_mb = 0.0; // RssAnon at READY=1
  std::size_t samples_sent = 0;  // published
  std::size_t samples_seen = 0;  // by mpmd's status when measured (all of them)
  std::size_t samples_used = 0;  // of those, used by the monitor (lags filled)
  std::string url;            // LCM URL used
};

// nullopt and `why` (with the last line mpmd wrote to stderr when it has
// one) when mpmd does not start, never says READY=1, dies, or does not
// confirm the samples; the child is stopped and reaped in every case.
std::optional<MpmdMemory> measure_mpmd_memory(const MpmdRun& run, std::string& why);

}  // namespace mpm::bench
