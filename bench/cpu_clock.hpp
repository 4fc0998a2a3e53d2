// CPU time of the calling thread. The timings use it rather than wall time:
// on a shared machine (builds of others running) wall time counts the time
// the thread waited for a core, which is not the monitor's cost.
#pragma once

#include <time.h>

namespace mpm::bench {

inline double thread_cpu_seconds() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

}  // namespace mpm::bench
