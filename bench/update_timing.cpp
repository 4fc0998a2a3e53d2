#include "bench/update_timing.hpp"

#include <algorithm>
#include <vector>

#include "tests/support/alloc_counter.hpp"
#include "bench/cpu_clock.hpp"
#include "bench/workload.hpp"

namespace mpm::bench {

namespace {

// Reads what `reads` says; the sum keeps the reads from being optimised away.
double read_after_update(const GrangerMonitor& m, Reads reads) noexcept {
  double sum = 0.0;
  for (std::size_t j = 0; j < m.n_outputs(); ++j) {
    if (reads == Reads::kEveryStatistic) sum += m.loop(j).lr_joint;
    for (std::size_t i = 0; i < m.n_inputs(); ++i) {
      if (reads == Reads::kAlarmsOnly) {
        sum += m.channel_alarm(j, i) ? 1.0 : 0.0;
        continue;
      }
      const ChannelStats& c = m.channel(j, i);
      sum += c.lr_conditional + c.lr_pairwise + c.gamma;
    }
  }
  return sum;
}

}  // namespace

UpdateTiming time_updates(std::size_t inputs, std::size_t outputs, std::size_t updates_per_repeat,
                          std::size_t repeats, Reads reads) {
  // A few thousand distinct samples keep the data realistic without making
  // the 50x50 workload large.
  const std::size_t samples = std::max<std::size_t>(64, std::min<std::size_t>(4096, 200000 / (inputs + outputs)));
  const Workload w = make_workload(inputs, outputs, samples);
  auto monitor = make_monitor(inputs, outputs);
  std::size_t k = warm_up(*monitor, w, 0);

  std::vector<double> per_update(repeats);
  UpdateTiming t;
  double sum = 0.0;
  {
    test::AllocationScope scope;
    for (std::size_t r = 0; r < repeats; ++r) {
      const double start = thread_cpu_seconds();
      for (std::size_t i = 0; i < updates_per_repeat; ++i, ++k) {
        monitor->update(w.u_at(k), w.residual_at(k));
        sum += read_after_update(*monitor, reads);
      }
      per_update[r] = (thread_cpu_seconds() - start) * 1e9 / static_cast<double>(updates_per_repeat);
    }
    t.allocations = scope.count();
  }
  volatile double keep = sum;  // the reads are part of the work timed
  (void)keep;
  t.updates = updates_per_repeat * repeats;
  t.ns_min = *std::min_element(per_update.begin(), per_update.end());
  std::nth_element(per_update.begin(), per_update.begin() + static_cast<std::ptrdiff_t>(repeats / 2), per_update.end());
  t.ns_per_update = per_update[repeats / 2];
  return t;
}

}  // namespace mpm::bench
