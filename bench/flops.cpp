#include "bench/flops.hpp"

#include <algorithm>

#include "bench/cpu_clock.hpp"

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace mpm::bench {
namespace {

// givens(a, b, first, end): x*x + y*y, sqrt, two divisions, then 4 mul +
// 2 add for each of the `tail` columns after `first`.
double givens_flops(std::size_t tail) { return 6.0 + 6.0 * static_cast<double>(tail); }

// absorb(first) on an augmented row of n = p + 1: one rotation per row i in
// [first, n), each over the columns after i.
double absorb_flops(std::size_t first, std::size_t n) {
  double f = 0.0;
  for (std::size_t i = first; i < n; ++i) f += givens_flops(n - 1 - i);
  return f;
}

}  // namespace

double sqrt_rls_update_flops(std::size_t p, bool forgetting) {
  const std::size_t n = p + 1;
  double f = absorb_flops(0, n);  // the data row
  if (forgetting) {
    f += static_cast<double>(n * (n + 1) / 2);  // scale R by sqrt(lambda)
    double prior = 0.0;
    for (std::size_t i = 0; i < p; ++i) prior += absorb_flops(i, n);
    f += prior / static_cast<double>(p) + 4.0;  // + the prior row's weight
  }
  return f;
}

double rss_without_flops(std::size_t p, std::size_t first, std::size_t count) {
  const std::size_t n = p + 1;
  if (count == 0) return 2.0 * 1.0;
  if (first + count >= n) return 2.0 * static_cast<double>(n - first);
  const std::size_t rows = n - first;
  const std::size_t cols = n - first - count;
  double f = 0.0;
  for (std::size_t c = 0; c + 1 < cols; ++c) {
    const std::size_t last_row = std::min(rows - 1, c + count);
    for (std::size_t r = c + 1; r <= last_row; ++r) f += givens_flops(cols - 1 - c);
  }
  return f + 2.0 * static_cast<double>(rows - cols + 1);
}

MonitorFlops monitor_flops(std::size_t inputs, std::size_t outputs, std::size_t na, std::size_t nb, bool forgetting) {
  const std::size_t p_full = 1 + na + inputs * nb;
  const std::size_t p_pair = 1 + na + nb;
  const auto m = static_cast<double>(inputs);
  const auto n_out = static_cast<double>(outputs);
  MonitorFlops f;
  f.full_updates = n_out * sqrt_rls_update_flops(p_full, forgetting);
  f.pairwise_updates = n_out * m * sqrt_rls_update_flops(p_pair, forgetting);
  double conditional = 0.0;
  for (std::size_t i = 0; i < inputs; ++i) conditional += rss_without_flops(p_full, 1 + na + i * nb, nb);
  f.conditional = n_out * conditional;
  // Per output: three prefix sums of squares (full, AR-only, intercept-only)
  // and three divisions. Per channel: a division, a log and a multiply for
  // each of the two indices, the pairwise prefix sums, a back-substitution of
  // the pairwise model (k^2 for k = p_pair) and gamma's two norms over na.
  const double per_output = 2.0 * (1.0 + static_cast<double>(nb * inputs + 1) + static_cast<double>(p_full)) + 3.0;
  const double per_channel = 6.0 + 2.0 * (1.0 + static_cast<double>(nb + 1)) +
                             static_cast<double>(p_pair * p_pair) + 5.0 * static_cast<double>(na) + 2.0;
  f.other_statistics = n_out * (per_output + m * per_channel);
  return f;
}

namespace {

constexpr int kChains = 12;
constexpr long kInner = 1000;

// Each kernel runs `rounds` x kInner steps of kChains independent FMAs
// acc = acc * mul + add (mul slightly below 1 keeps the values finite).
#if defined(__x86_64__)
__attribute__((target("avx512f"))) double fma_avx512(long rounds) {
  __m512d acc[kChains];
  for (int c = 0; c < kChains; ++c) acc[c] = _mm512_set1_pd(1.0 + c);
  const __m512d mul = _mm512_set1_pd(0.999999), add = _mm512_set1_pd(1e-6);
  for (long r = 0; r < rounds; ++r)
    for (long i = 0; i < kInner; ++i)
      for (int c = 0; c < kChains; ++c) acc[c] = _mm512_fmadd_pd(acc[c], mul, add);
  // Stored and summed by hand: GCC 12's _mm512_reduce_add_pd warns here.
  alignas(64) double out[8];
  double s = 0.0;
  for (int c = 0; c < kChains; ++c) {
    _mm512_store_pd(out, acc[c]);
    for (double v : out) s += v;
  }
  return s;
}

__attribute__((target("avx2,fma"))) double fma_avx2(long rounds) {
  __m256d acc[kChains];
  for (int c = 0; c < kChains; ++c) acc[c] = _mm256_set1_pd(1.0 + c);
  const __m256d mul = _mm256_set1_pd(0.999999), add = _mm256_set1_pd(1e-6);
  for (long r = 0; r < rounds; ++r)
    for (long i = 0; i < kInner; ++i)
      for (int c = 0; c < kChains; ++c) acc[c] = _mm256_fmadd_pd(acc[c], mul, add);
  alignas(32) double out[4];
  double s = 0.0;
  for (int c = 0; c < kChains; ++c) {
    _mm256_store_pd(out, acc[c]);
    s += out[0] + out[1] + out[2] + out[3];
  }
  return s;
}
#endif

double mul_add_sse2(long rounds) {  // what the portable build emits: mul + add
  double acc[kChains][2];
  for (int c = 0; c < kChains; ++c) acc[c][0] = acc[c][1] = 1.0 + c;
  for (long r = 0; r < rounds; ++r)
    for (long i = 0; i < kInner; ++i)
      for (int c = 0; c < kChains; ++c)
        for (int l = 0; l < 2; ++l) acc[c][l] = acc[c][l] * 0.999999 + 1e-6;
  double s = 0.0;
  for (int c = 0; c < kChains; ++c) s += acc[c][0] + acc[c][1];
  return s;
}

volatile double g_sink = 0.0;

// Flop rate of `kernel` (lanes doubles per vector, 2 flops per lane-step),
// run long enough to take about `seconds`.
template <typename Kernel>
double rate(Kernel kernel, int lanes, double seconds) {
  long rounds = 1;
  for (;;) {
    const double start = thread_cpu_seconds();
    g_sink = g_sink + kernel(rounds);
    const double t = thread_cpu_seconds() - start;
    if (t >= seconds || rounds > (1L << 40)) {
      return 2.0 * lanes * kChains * static_cast<double>(kInner) * static_cast<double>(rounds) / t;
    }
    rounds = t > 1e-4 ? static_cast<long>(static_cast<double>(rounds) * seconds / t * 1.1) + 1 : rounds * 10;
  }
}

}  // namespace

PeakRate measure_peak(double seconds) {
  PeakRate best{rate(mul_add_sse2, 2, seconds), "SSE2 mul+add, 12 chains x 2 doubles"};
#if defined(__x86_64__)
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) {
    const double r = rate(fma_avx2, 4, seconds);
    if (r > best.flops_per_s) best = {r, "AVX2 FMA, 12 chains x 4 doubles"};
  }
  if (__builtin_cpu_supports("avx512f")) {
    const double r = rate(fma_avx512, 8, seconds);
    if (r > best.flops_per_s) best = {r, "AVX-512 FMA, 12 chains x 8 doubles"};
  }
#endif
  return best;
}

}  // namespace mpm::bench
