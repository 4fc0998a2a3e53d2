// CPU-time cost of GrangerMonitor::update() on pre-generated data, with the
// heap allocations counted over the timed updates.
#pragma once

#include <cstddef>
#include <cstdint>

namespace mpm::bench {

struct UpdateTiming {
  double ns_per_update = 0.0;     // median over the repeats
  double ns_min = 0.0;            // fastest repeat (least disturbed by load)
  std::size_t updates = 0;        // timed updates in all
  std::int64_t allocations = 0;   // heap allocations during the timed updates
};

// What is read after each update: every statistic of every channel and
// loop (the monitor computes the RSS-based ones when read), or only the
// channels' alarm flags, as mpmd does per sample (its status, which reads
// the statistics, goes out once a period).
enum class Reads { kEveryStatistic, kAlarmsOnly };

// Builds a monitor (paper orders, gamma on), warms it until samples are used,
// then times `repeats` runs of `updates_per_repeat` used updates, each
// followed by the reads.
UpdateTiming time_updates(std::size_t inputs, std::size_t outputs, std::size_t updates_per_repeat,
                          std::size_t repeats, Reads reads = Reads::kEveryStatistic);

}  // namespace mpm::bench
