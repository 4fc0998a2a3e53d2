// Resident memory of a small process holding one monitor, as a proxy for
// mpmd: a forked child builds the monitor, runs a few updates (touching all
// its storage) and reports VmRSS / VmHWM from /proc/self/status.
#pragma once

#include <cstddef>
#include <optional>
#include <string>

namespace mpm::bench {

struct ResidentMemory {
  double rss_mb = 0.0;       // VmRSS with the monitor
  double hwm_mb = 0.0;       // VmHWM (peak, includes setup copies)
  double baseline_mb = 0.0;  // VmRSS of the child before building it
};

// nullopt with `why` set when fork or /proc is unavailable.
std::optional<ResidentMemory> measure_monitor_memory(std::size_t inputs, std::size_t outputs, std::string& why);

// VmRSS and VmHWM of this process in MB, from /proc/self/status (0 if absent).
double status_field_mb(const char* field);

}  // namespace mpm::bench
