#include "bench/flops.hpp"

#include <algorithm>
#include <cmath>

#include "bench/cpu_clock.hpp"
#include "core/givens.hpp"
#include "core/rls_common.hpp"

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace mpm::bench {
namespace {

// Mirrors of constants private to the core (keep in step with it).
constexpr std::size_t kWaldMinInputs = 4;  // core/granger_monitor.cpp

double d(std::size_t n) { return static_cast<double>(n); }

// rotate(a, b, first, end, scale): x = scale a[first], 1 / sqrt(x^2 + y^2)
// (mul, mul, add, sqrt, div), c, s, c scale, s scale (4 mul), the new pivot
// x c + y s (3): 13; then 2 x (2 mul + 1 add) for each of the `tail` columns
// after `first`. The scale's products are done even when scale = 1.
double rotation_flops(std::size_t tail) { return 13.0 + 6.0 * d(tail); }

// absorb(first, scale) of a row of p regressors + target into R: rotations
// i = first..p over the columns after i.
double absorb_flops(std::size_t first, std::size_t p) {
  double f = 0.0;
  for (std::size_t i = first; i <= p; ++i) f += rotation_flops(p - i);
  return f;
}

// rotate_sqrt_free(u, d, b, w, first, end, lambda): lambda d, w x, the new
// weight lambda d + w x x (2), its reciprocal, cbar, sbar, w cbar: 8; then
// b - x u (2) and cbar u + sbar b (3) for each of the `tail` columns after
// `first`.
double ud_rotation_flops(std::size_t tail) { return 8.0 + 5.0 * d(tail); }

// UdRls absorbing a row of p regressors + target from row `first` on.
double ud_absorb_flops(std::size_t first, std::size_t p) {
  double f = 0.0;
  for (std::size_t i = first; i <= p; ++i) f += ud_rotation_flops(p - i);
  return f;
}

// Sum of squares of `terms` values: a multiply and an add each.
double sum_of_squares_flops(std::size_t terms) { return 2.0 * d(terms); }

// SqrtRls::rss_prefix(k) of a model with p regressors: rows k..p.
double rss_prefix_flops(std::size_t p, std::size_t k) { return sum_of_squares_flops(p + 1 - k); }
// UdRls::rss_prefix(k): d_p, then d_i z_i^2 added for rows k..p-1 (3 each).
double ud_rss_prefix_flops(std::size_t p, std::size_t k) { return 3.0 * d(p - k); }

}  // namespace

int prior_refresh_period(std::size_t p, double lambda) { return KeptAlivePrior(p, lambda, 1.0).period(); }

double sqrt_rls_update_flops(std::size_t p, double lambda) {
  double f = absorb_flops(0, p);  // the data row, sqrt(lambda) folded in
  if (lambda < 1.0) {
    // refresh_prior: every K samples a unit row at a round-robin index r in
    // [0, p), absorbed from row r with scale 1.
    double prior = 0.0;
    for (std::size_t r = 0; r < p; ++r) prior += absorb_flops(r, p);
    f += prior / d(p) / static_cast<double>(prior_refresh_period(p, lambda));
  }
  return f;
}

double ud_rls_update_flops(std::size_t p, double lambda) {
  double f = ud_absorb_flops(0, p);
  if (lambda < 1.0) {
    double prior = 0.0;
    for (std::size_t r = 0; r < p; ++r) prior += ud_absorb_flops(r, p);
    f += prior / d(p) / static_cast<double>(prior_refresh_period(p, lambda));
  }
  return f;
}

double ud_rss_without_flops(std::size_t p, std::size_t first, std::size_t count) {
  if (count == 0) return ud_rss_prefix_flops(p, p);
  if (first + count >= p + 1) return ud_rss_prefix_flops(p, first);
  // The rows of R = D^1/2 U copied into scratch: a square root per row and a
  // product per copied entry; then SqrtRls's re-triangularisation.
  const std::size_t rows = p + 1 - first;
  const std::size_t cols = p + 1 - first - count;
  return d(rows) * (1.0 + d(cols)) + rss_without_flops(p, first, count);
}

double ud_solve_prefix_flops(std::size_t k) {
  // Unit diagonal: coefficient i costs its i multiply-subtracts only.
  double f = 0.0;
  for (std::size_t i = 0; i < k; ++i) f += 2.0 * d(i);
  return f;
}

double bierman_update_flops(std::size_t p, std::size_t block, double lambda) {
  // absorb() from column `first` on: the a priori error (2p); per column j
  // of U (padded(j) rows): the dot product with h (2 each), f, g, alpha (4),
  // the new d (3), p_j (1), the column and gain update (4 each); the gain
  // step k (1), beta += gain k (2p), the RSS (3) and the target's energy
  // (4); the block covariances' downdates (per row 1, per lower-triangle
  // entry 3).
  const auto absorb = [&](std::size_t first) {
    double f = 2.0 * d(p) + 1.0 + 2.0 * d(p) + 3.0 + 4.0 + 1.0;
    for (std::size_t j = first; j < p; ++j) f += 6.0 * d(givens::padded(j)) + 8.0;
    for (std::size_t r = 0; r < block; ++r) f += d(p / block) * (1.0 + 3.0 * d(r + 1));
    return f;
  };
  double f = absorb(0);
  // One block's covariance from U and D per sample, averaged over the
  // round robin: per column k >= b0, per stored row a its (a + 1) entries
  // (1 + 2 (a + 1)), and the diagonal's row inside the block.
  double resync = 0.0;
  for (std::size_t b0 = 0; b0 < p; b0 += block)
    for (std::size_t k = b0; k < p; ++k) {
      const std::size_t stored = std::min(block, k - b0);
      for (std::size_t a = 0; a < stored; ++a) resync += 1.0 + 2.0 * d(a + 1);
      if (stored < block) resync += 2.0 * d(stored) + 1.0;
    }
  f += resync / d(p / block);
  if (lambda < 1.0) {
    // The prior's unit row every K samples, from its round-robin column on.
    double prior = 0.0;
    for (std::size_t r = 0; r < p; ++r) prior += absorb(r);
    f += prior / d(p) / static_cast<double>(prior_refresh_period(p, lambda));
  }
  return f;
}

double rss_without_flops(std::size_t p, std::size_t first, std::size_t count) {
  const std::size_t n = p + 1;
  if (count == 0) return rss_prefix_flops(p, p);
  if (first + count >= n) return rss_prefix_flops(p, first);
  const std::size_t rows = n - first;
  const std::size_t cols = n - first - count;
  double f = 0.0;
  for (std::size_t c = 0; c + 1 < cols; ++c) {
    const double h = d(std::min(rows - 1, c + count) - c);  // entries below the diagonal
    const double w = d(cols - 1 - c);                       // columns right of c
    // sigma (2h); norm: mul, add, sqrt; v0: add; tau: mul, add, div.
    f += 2.0 * h + 7.0;
    // proj = v0 pivot (w) + sum_r v_r row_r (2hw); *= tau (w); pivot -= v0
    // proj (2w); rows -= v_r proj (2hw).
    f += w * (4.0 + 4.0 * h);
  }
  return f + sum_of_squares_flops(rows - cols + 1);
}

namespace {

// The Cholesky of a count x count block and the forward solve of g
// (bierman_rls.cpp, wald_quadratic): row a: for each b <= a a dot product of b
// terms (2b) and a division or the square root; the solve: 2a, a division,
// and quad += t^2 (2).
double wald_quadratic_flops(std::size_t count) {
  double f = 0.0;
  for (std::size_t a = 0; a < count; ++a) {
    for (std::size_t b = 0; b <= a; ++b) f += 2.0 * d(b) + 1.0;
    f += 2.0 * d(a) + 3.0;
  }
  return f;
}

}  // namespace

namespace {

// update_statistics for one output, everything but the conditional RSS.
// NestedRls of the output: prefix a = 1 + na, lower factor of P = m nb
// regressors, pairwise factors of nb (the first input's: a prefix of the
// lower factor).
double statistics_flops(std::size_t inputs, std::size_t na, std::size_t nb, bool gamma, bool wald) {
  const std::size_t a = 1 + na;
  const std::size_t p_lower = inputs * nb;
  // The lower factor's RSS values: prefix sums of a UdRls, or tracked
  // (free) in the covariance form.
  const auto lower_rss_prefix = [&](std::size_t k) { return wald ? 0.0 : ud_rss_prefix_flops(p_lower, k); };
  // rss_full, rss_prefix_only, rss_head(1) (rss_prefix_only again plus the
  // a - 1 trapezoid rows' d z^2, 3 each); three divisions by sum_w;
  // lr_joint: division, log, product; gamma_lambda^2.
  double f = lower_rss_prefix(p_lower) + 2.0 * lower_rss_prefix(0) + 3.0 * d(a - 1) + 1.0 + 3.0 + 3.0 + 1.0;
  for (std::size_t i = 0; i < inputs; ++i) {
    f += 3.0;  // f_conditional (division, log), lr_conditional
    // Pairwise F: its A-only RSS and its RSS (input 0 without the covariance
    // form: prefix sums of the lower factor; else the pairwise UdRls's),
    // division, log, product.
    f += i == 0 && !wald ? lower_rss_prefix(0) + lower_rss_prefix(nb)
                         : ud_rss_prefix_flops(nb, 0) + ud_rss_prefix_flops(nb, nb);
    f += 3.0;
    if (gamma) {
      // solve_pairs_prefix, this input's share: nb coefficients of its block
      // (unit back substitution), the trapezoid's right-hand side (a rows of
      // nb multiply-subtracts) and the back substitution with the unit U_AA
      // (a (a - 1) / 2 multiply-subtracts); |g_hat - g_N|^2: na
      // subtractions, na products, na - 1 adds; 1 + |g_N|^2: 2 na; the
      // quotient: 1.
      f += ud_solve_prefix_flops(nb) + 2.0 * d(a) * d(nb) + d(a) * d(a - 1);
      f += 3.0 * d(na) - 1.0 + 2.0 * d(na) + 1.0;
    }
  }
  return f;
}

// push_lags per channel: u - ref, the model filter's step (a multiply-add
// per coefficient), x_1 = a x_1 + gain source (3), x_r = a x_r + x_{r-1}old
// - a x_{r-1} (4 each, also when a = 0: the products are done).
double channel_push_flops(std::size_t nb, std::size_t filter_taps) {
  return 1.0 + 2.0 * d(filter_taps) + 3.0 + 4.0 * d(nb - 1);
}

}  // namespace

MonitorFlops monitor_flops(std::size_t inputs, std::size_t outputs, const MonitorSettings& settings,
                           const MonitorFlopsOptions& options) {
  const auto na = static_cast<std::size_t>(settings.ar_order);
  const auto nb = static_cast<std::size_t>(settings.input_order);
  const double lambda = settings.forgetting;
  const std::size_t a = 1 + na;
  const std::size_t p_lower = inputs * nb;
  const std::size_t cols = a + p_lower + 1;
  const bool wald = inputs >= kWaldMinInputs;
  const double n_out = d(outputs);
  MonitorFlops f;
  // NestedRls per output: the trapezoid of the a prefix rows (square-root
  // free rotation i over the columns after i), the lower factor, and every
  // K_a samples the trapezoid's prior row (from a round-robin row r) passed
  // on to the lower and pairwise factors.
  double shared = 0.0;
  for (std::size_t i = 0; i < a; ++i) shared += ud_rotation_flops(cols - 1 - i);
  shared += wald ? bierman_update_flops(p_lower, nb, lambda) : ud_rls_update_flops(p_lower, lambda);
  if (lambda < 1.0) {
    double prior = 0.0;
    for (std::size_t r = 0; r < a; ++r)
      for (std::size_t i = r; i < a; ++i) prior += ud_rotation_flops(cols - 1 - i);
    prior /= d(a);
    // Passed on: the covariance form's absorb() without forgetting, counted
    // as a whole update (its resync included: an upper bound); or UdRls's.
    prior += wald ? bierman_update_flops(p_lower, nb, 1.0) : ud_absorb_flops(0, p_lower);
    prior += d(wald ? inputs : inputs - 1) * ud_absorb_flops(0, nb);
    shared += prior / static_cast<double>(prior_refresh_period(a, lambda));
  }
  f.full_updates = n_out * shared;
  f.pairwise_updates = n_out * d(wald ? inputs : inputs - 1) * ud_rls_update_flops(nb, lambda);
  // rss_without_block: one input, the prefix-only RSS; two, a pairwise RSS
  // or a prefix sum; more, re-triangularisation of the UdRls lower factor
  // (a prefix sum for the trailing block) or, in covariance form, the Wald
  // quadratic of the block's tracked covariance and coefficients.
  double conditional = 0.0;
  for (std::size_t i = 0; i < inputs; ++i) {
    const std::size_t first = i * nb;
    if (inputs == 1) conditional += ud_rss_prefix_flops(p_lower, 0);
    else if (inputs == 2) conditional += i == 0 ? ud_rss_prefix_flops(nb, nb) : ud_rss_prefix_flops(p_lower, nb);
    else if (!wald) conditional += ud_rss_without_flops(p_lower, first, nb);
    else conditional += wald_quadratic_flops(nb) + 1.0;
  }
  f.conditional = n_out * conditional;
  // absorb_sample's weights (sum_w 2, sum_w2 3, n_eq 2) and update_statistics'
  // two scales (2), once per update.
  f.other_statistics = 9.0 + n_out * statistics_flops(inputs, na, nb, options.gamma, wald);
  // gain = sqrt(1 - a^2) once; per output the divergence check (dev 1, mean
  // 2, variance 4, baseline test 1; the reference test 1 only when known,
  // not counted); per channel the regressor push.
  f.lags = 3.0 + n_out * 8.0 + n_out * d(inputs) * channel_push_flops(nb, options.filter_taps);
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
