// Offline replay throughput: a recording of the Wood-Berry column (2x2, the
// paper's first case study) pushed through ResidualGenerator + GrangerMonitor
// as `mpm monitor` and mpmd do per sample.
#pragma once

#include <cstddef>
#include <cstdint>

namespace mpm::bench {

struct ReplayResult {
  double samples_per_s = 0.0;           // one thread, thread CPU time
  double parallel_samples_per_s = 0.0;  // as `mpm monitor` runs it: residuals,
                                        // then the outputs over `threads`
                                        // threads; wall-clock time, median
                                        // of kParallelRuns runs
  double parallel_runs[3] = {};         // each run's rate
  static constexpr int kParallelRuns = 3;
  std::size_t threads = 1;
  bool parallel_identical = false;      // the split changed no statistic
  std::size_t samples = 0;
  std::int64_t allocations = 0;  // during the timed replay (must be 0)
};

// Generates `samples` samples in memory (random inputs through the plant,
// AR noise through N), then times the replay of all of them.
ReplayResult measure_replay(std::size_t samples);

}  // namespace mpm::bench
