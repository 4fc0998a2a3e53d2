// One-way LCM latency over UDP multicast on this host (ttl=0): a message is
// published from one thread and received by another LCM instance in a second
// thread; one message in flight at a time (no queueing in the figure).
#pragma once

#include <cstddef>
#include <optional>
#include <string>

namespace mpm::bench {

struct Latency {
  double p50_us = 0.0;
  double p99_us = 0.0;
  std::size_t messages = 0;  // received and timed
  std::size_t lost = 0;      // not received within the per-message timeout
};

// nullopt with `why` when LCM is not built in, cannot start (e.g. no
// multicast route) or delivers nothing.
std::optional<Latency> measure_lcm_latency(std::size_t messages, std::string& why);

}  // namespace mpm::bench
