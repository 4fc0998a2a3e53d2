// Floating-point work of one monitor update, counted analytically from the
// algorithm in core/sqrt_rls.cpp and core/granger_monitor.cpp, and the
// core's peak rate, measured by an FMA-throughput loop.
//
// Counting convention: one add, multiply, divide, square root or log is one
// flop (an FMA is two). Loops are counted as the core runs them on dense data
// (no zero is skipped: random data has none).
#pragma once

#include <cstddef>
#include <string>

namespace mpm::bench {

// Flops of SqrtRls::update with p regressors. With forgetting < 1 it also
// scales R and absorbs one prior row starting at a round-robin index; that
// cost is averaged over the p possible starting rows.
double sqrt_rls_update_flops(std::size_t p, bool forgetting);
// Flops of SqrtRls::rss_without(first, count) for p regressors.
double rss_without_flops(std::size_t p, std::size_t first, std::size_t count);

struct MonitorFlops {
  double full_updates = 0.0;      // one SqrtRls per output, p = 1 + na + m nb
  double pairwise_updates = 0.0;  // one per (output, input), p = 1 + na + nb
  double conditional = 0.0;       // rss_without per (output, input)
  double other_statistics = 0.0;  // prefix RSS, logs, gamma (back-substitution)
  double total() const { return full_updates + pairwise_updates + conditional + other_statistics; }
};
// One used sample of GrangerMonitor::update with every statistic and gamma.
MonitorFlops monitor_flops(std::size_t inputs, std::size_t outputs, std::size_t na, std::size_t nb, bool forgetting);

struct PeakRate {
  double flops_per_s = 0.0;  // best of the vector widths this CPU runs
  std::string how;           // which instruction set and loop gave it
};
// Independent chains of fused multiply-adds (12 accumulators, enough to cover
// latency x throughput) on the widest vectors the CPU supports (AVX-512,
// AVX2+FMA, or SSE2 mul+add), one thread, for about `seconds`.
PeakRate measure_peak(double seconds);

}  // namespace mpm::bench
