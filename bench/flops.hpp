// Floating-point work of one monitor update, counted analytically from the
// algorithm in tests/support/sqrt_rls.cpp, core/ud_rls.cpp, core/nested_rls.cpp and
// core/granger_monitor.cpp, and the
// core's peak rate, measured by an FMA-throughput loop.
//
// Counting convention: every add, subtract, multiply, divide and square root
// is one flop, a multiply-add is two (so an FMA counts 2, whether or not the
// compiler fuses it), and a log is one. Loops are counted as the core runs
// them on dense data (no zero is skipped: random data has none). Copies,
// comparisons and index arithmetic are not flops.
//
// The counts mirror the current loops line by line (see each function in
// flops.cpp); kWaldMinInputs, private to the core, is repeated there and
// must move with it.
#pragma once

#include <cstddef>
#include <string>

#include "core/granger_monitor.hpp"

namespace mpm::bench {

// Flops of SqrtRls::update with p regressors and forgetting lambda: one
// Givens rotation per row of [R | target] with sqrt(lambda) folded in, plus,
// when lambda < 1, the kept-alive prior row re-absorbed every K samples
// (averaged over K and over the p round-robin starting rows).
double sqrt_rls_update_flops(std::size_t p, double lambda);
double sqrt_rls_update_flops(std::size_t, bool) = delete;  // lambda is a number, not a flag
// The same for UdRls (square-root-free rotations).
double ud_rls_update_flops(std::size_t p, double lambda);
double ud_rls_update_flops(std::size_t, bool) = delete;
// BiermanRls::update with p regressors in blocks of `block`: the one pass
// over U, the tracked coefficients, RSS and block covariances, one block's
// resync, and the prior row every K samples.
double bierman_update_flops(std::size_t p, std::size_t block, double lambda);
// The prior's refresh period K the core uses for p regressors and lambda
// (core/givens.hpp).
int prior_refresh_period(std::size_t p, double lambda);
// Flops of SqrtRls::rss_without(first, count) for p regressors (Householder
// re-triangularisation of the trailing block).
double rss_without_flops(std::size_t p, std::size_t first, std::size_t count);
// The same for UdRls::rss_without (R's rows formed from D and U first).
double ud_rss_without_flops(std::size_t p, std::size_t first, std::size_t count);
// Flops of UdRls::solve_prefix(k) (unit diagonal).
double ud_solve_prefix_flops(std::size_t k);

struct MonitorFlops {
  double full_updates = 0.0;      // one NestedRls per output: the shared rows of
                                  // [1, AR] and the lower factor of m nb (a
                                  // BiermanRls when m >= kWaldMinInputs,
                                  // else a UdRls)
  double pairwise_updates = 0.0;  // pairwise lower factors of nb per output:
                                  // m - 1 (the first input's is a prefix of a
                                  // UdRls lower factor), m with a BiermanRls
  double conditional = 0.0;       // rss_without_block per (output, input)
  double other_statistics = 0.0;  // prefix RSS, logs, gamma (solve_prefix), n_eq
  double lags = 0.0;              // per-sample regressor pushes (Laguerre/lag
                                  // network, model filters), divergence check
  double total() const { return full_updates + pairwise_updates + conditional + other_statistics + lags; }
};

// What the monitor computes besides the fixed parts.
struct MonitorFlopsOptions {
  bool gamma = true;              // noise models given: gamma per channel
  std::size_t filter_taps = 0;    // model-filtered regressors: numerator +
                                  // denominator coefficients (leading 1
                                  // excluded) of every channel's DiscreteFilter;
                                  // 0 = plain lags (no filter)
};
// One used sample of GrangerMonitor::update with every statistic.
MonitorFlops monitor_flops(std::size_t inputs, std::size_t outputs, const MonitorSettings& settings,
                           const MonitorFlopsOptions& options = {});

struct PeakRate {
  double flops_per_s = 0.0;  // best of the vector widths this CPU runs
  std::string how;           // which instruction set and loop gave it
};
// Independent chains of fused multiply-adds (12 accumulators, enough to cover
// latency x throughput) on the widest vectors the CPU supports (AVX-512,
// AVX2+FMA, or SSE2 mul+add), one thread, for about `seconds`.
PeakRate measure_peak(double seconds);

}  // namespace mpm::bench
