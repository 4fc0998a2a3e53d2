// Offline throughput of `mpm diagnose`: a closed-loop Wood-Berry recording
// with a planted mismatch (scenario wood-berry-g21-gain) written to temporary
// files, then the command's whole pipeline timed on it (load and parse the
// plant and the recording, bind, residuals, the Granger monitor over the
// record, the structured hypotheses of core/diagnosis.hpp). Its peak memory
// is that of the real command: `mpm diagnose` (this program, when it is mpm)
// run once more as a child on the same files, its peak resident set (VmHWM)
// read from /proc while it runs.
#pragma once

#include <cstddef>
#include <optional>
#include <string>

namespace mpm::bench {

struct DiagnoseThroughput {
  double samples_per_s = 0.0;          // median over the repeats, wall-clock time
  double fastest_samples_per_s = 0.0;
  double cpu_seconds = 0.0;            // process CPU time of the median run (all threads)
  double wall_seconds = 0.0;           // wall-clock time of the median run
  std::size_t samples = 0;
  std::size_t repeats = 0;
  std::size_t threads = 1;             // threads of the monitor run (replay_threads)
  std::string scenario;
  std::string planted;                 // "y2 <- u1": the scenario's edited channels
  bool found_planted = false;          // every run's findings name every planted channel
  std::string findings;                // the findings' summaries, "; "-separated
  std::optional<double> peak_rss_mb;   // the `mpm diagnose` child's maximum resident set, MB
  std::string rss_note;                // how it was measured, or why not
};

// Simulates `samples` samples of the scenario (seed 1, as `mpm simulate`
// defaults to), writes plant and recording to a temporary folder (removed
// again), and times `repeats` runs of the diagnose pipeline on them. Returns
// nullopt with `why` set when something fails (no temporary folder, ...).
std::optional<DiagnoseThroughput> measure_diagnose(std::size_t samples, std::size_t repeats, std::string& why);

}  // namespace mpm::bench
