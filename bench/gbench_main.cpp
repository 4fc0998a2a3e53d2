// Google Benchmark suite of issue 4. Sizes are n inputs x n outputs with the
// paper's orders (na = 20, nb = 10), every statistic and gamma on. The 20x20
// and 50x50 cases take tens of ms to seconds per update: their iteration
// counts are fixed and small. Counters: flops per update (analytic, see
// flops.hpp), the achieved rate, and the fraction of the peak measured by
// BM_FmaPeak's kernel in the same run.
#include <benchmark/benchmark.h>

#include "tests/support/alloc_counter.hpp"
#include "bench/batch_baseline.hpp"
#include "bench/flops.hpp"
#include "bench/replay.hpp"
#include "bench/workload.hpp"
#include "core/bierman_rls.hpp"
#include "tests/support/sqrt_rls.hpp"
#include "core/ud_rls.hpp"

namespace mpm::bench {
namespace {

const PeakRate& peak() {
  static const PeakRate p = measure_peak(0.2);
  return p;
}

void BM_MonitorUpdate(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  const Workload w = make_workload(n, n, std::max<std::size_t>(64, std::min<std::size_t>(4096, 100000 / n)));
  auto monitor = make_monitor(n, n);
  std::size_t k = warm_up(*monitor, w, 0);
  std::int64_t allocations = 0;
  {
    test::AllocationScope scope;
    for (auto _ : state) {
      benchmark::DoNotOptimize(monitor->update(w.u_at(k), w.residual_at(k)));
      ++k;
    }
    allocations = scope.count();
  }
  const MonitorSettings s = paper_settings();
  const double flops = monitor_flops(n, n, s).total();
  state.counters["flops_per_update"] = flops;
  state.counters["flop_rate"] = benchmark::Counter(flops, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["allocations"] = static_cast<double>(allocations);
  state.counters["peak_flop_rate"] = peak().flops_per_s;
}
BENCHMARK(BM_MonitorUpdate)->Arg(2)->Arg(4)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_MonitorUpdate)->Arg(20)->Iterations(10)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_MonitorUpdate)->Arg(50)->Iterations(2)->Unit(benchmark::kMillisecond);

void BM_SlidingWindowBatch2x2(benchmark::State& state) {
  const MonitorSettings s = paper_settings();
  const Workload w = make_workload(2, 2, 2600, 3);
  SlidingWindowBatch batch(w, s.ar_order, s.input_order, 2000);
  std::size_t k = 0;
  for (auto _ : state) benchmark::DoNotOptimize(batch.update(k++));
}
BENCHMARK(BM_SlidingWindowBatch2x2)->Iterations(20)->Unit(benchmark::kMillisecond);

void BM_Replay2x2(benchmark::State& state) {
  const auto samples = static_cast<std::size_t>(state.range(0));
  double rate = 0.0;
  for (auto _ : state) rate = measure_replay(samples).samples_per_s;  // includes generating it
  state.counters["samples_per_s"] = rate;
}
BENCHMARK(BM_Replay2x2)->Arg(1000000)->Iterations(1)->Unit(benchmark::kSecond);

// Parts of the update, for profiling: one update of each factor kind (p
// regressors; range(1) = 1: forgetting 0.999 with the prior row, 0: lambda =
// 1), and one conditional RSS (rss_without of the first input block).
// make(p, lambda) builds the factor, flops(p, lambda) counts one update's flops.
template <typename Make, typename Flops>
void update_factor(benchmark::State& state, Make make, Flops flops) {
  const auto p = static_cast<std::size_t>(state.range(0));
  const double lambda = state.range(1) ? 0.999 : 1.0;
  auto rls = make(p, lambda);
  const Workload w = make_workload(p, 1, 512);
  std::size_t k = 0;
  for (auto _ : state) {
    rls.update(w.u_at(k), w.residual_at(k)[0]);
    ++k;
  }
  benchmark::DoNotOptimize(rls.rss());
  state.counters["flops"] = flops(p, lambda);
}

void BM_SqrtRlsUpdate(benchmark::State& state) {
  update_factor(
      state, [](std::size_t p, double lambda) { return SqrtRls(p, lambda, 1e-9); },
      [](std::size_t p, double lambda) { return sqrt_rls_update_flops(p, lambda); });
}
BENCHMARK(BM_SqrtRlsUpdate)->ArgsProduct({{31, 41, 520}, {0, 1}});

void BM_UdRlsUpdate(benchmark::State& state) {
  update_factor(
      state, [](std::size_t p, double lambda) { return UdRls(p, lambda, 1e-9); },
      [](std::size_t p, double lambda) { return ud_rls_update_flops(p, lambda); });
}
BENCHMARK(BM_UdRlsUpdate)->ArgsProduct({{31, 41, 520}, {0, 1}});

// The monitor's lower factor from 4 inputs on (blocks of nb = 10).
void BM_BiermanRlsUpdate(benchmark::State& state) {
  update_factor(
      state, [](std::size_t p, double lambda) { return BiermanRls(p, 10, lambda, 1e-9); },
      [](std::size_t p, double lambda) { return bierman_update_flops(p, 10, lambda); });
}
BENCHMARK(BM_BiermanRlsUpdate)->ArgsProduct({{40, 500}, {0, 1}});

void BM_RssWithout(benchmark::State& state) {
  const auto p = static_cast<std::size_t>(state.range(0));
  const auto first = static_cast<std::size_t>(state.range(1));
  SqrtRls rls(p, 0.999, 1e-9);
  const Workload w = make_workload(p, 1, 512);
  for (std::size_t k = 0; k < 2 * p; ++k) rls.update(w.u_at(k), w.residual_at(k)[0]);
  SqrtRls::Matrix scratch(static_cast<Eigen::Index>(p + 1), static_cast<Eigen::Index>(p + 1));
  for (auto _ : state) benchmark::DoNotOptimize(rls.rss_without(first, 10, scratch));
  state.counters["flops"] = rss_without_flops(p, first, 10);
}
BENCHMARK(BM_RssWithout)->Args({41, 21})->Args({521, 21})->Args({521, 271});

void BM_FmaPeak(benchmark::State& state) {
  for (auto _ : state) state.counters["peak_flop_rate"] = measure_peak(0.05).flops_per_s;
}
BENCHMARK(BM_FmaPeak)->Iterations(3);

}  // namespace
}  // namespace mpm::bench

BENCHMARK_MAIN();
