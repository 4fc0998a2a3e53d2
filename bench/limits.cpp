#include "bench/limits.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <vector>

#include "core/givens.hpp"

namespace mpm::bench {
namespace {

constexpr std::size_t kWaldMinInputs = 4;  // core/granger_monitor.cpp (as in flops.cpp)

double d(std::size_t n) { return static_cast<double>(n); }

// Bytes of the upper (or lower) triangle of an n x n factor as the
// rotations touch it: row i from column i (rounded down to whole lanes) to
// the padded end.
double triangle_bytes(std::size_t n) {
  const std::size_t width = givens::padded(n);
  double values = 0.0;
  for (std::size_t i = 0; i < n; ++i) values += d(width - i / givens::kLanes * givens::kLanes);
  return 8.0 * values;
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

double state_bytes_per_update(std::size_t inputs, std::size_t outputs, const MonitorSettings& settings) {
  const auto na = static_cast<std::size_t>(settings.ar_order);
  const auto nb = static_cast<std::size_t>(settings.input_order);
  const std::size_t a = 1 + na;
  const std::size_t p = inputs * nb;                   // lower factor's regressors
  const std::size_t cols = givens::padded(a + p + 1);  // the shared rows' width
  double per_output = 8.0 * d(a) * (d(cols) + 1.0);    // [U_AA U_AB U_Ay] and D
  const bool wald = inputs >= kWaldMinInputs;
  if (wald) {                                          // lower factor in covariance form:
    double columns = 0.0;                              // U's columns above the diagonal,
    for (std::size_t j = 0; j < p; ++j) columns += d(givens::padded(j));
    per_output += 8.0 * (columns + d(p));              // D,
    per_output += 8.0 * d(p) * d(nb);                  // block covariances
  } else {
    per_output += triangle_bytes(p + 1);               // lower factor [U | z] (D is p values more)
  }
  per_output += d(wald ? inputs : inputs - 1) * triangle_bytes(nb + 1);  // pairwise factors
  return d(outputs) * per_output;
}

std::size_t rotation_chain_length(std::size_t inputs, const MonitorSettings& settings) {
  return 1 + static_cast<std::size_t>(settings.ar_order) + inputs * static_cast<std::size_t>(settings.input_order) + 1;
}

StreamRate measure_stream_rate(double bytes, double seconds) {
  // Two arrays of half the working set each; one pass reads both and writes
  // the first back, as a rotation does with a factor row and the data row.
  const auto n = static_cast<std::size_t>(std::max(bytes / 16.0, 1024.0));
  std::vector<double> x(n, 1.0), y(n, 0.5);
  StreamRate r;
  r.working_set = 16.0 * d(n);
  double best = 0.0;
  const auto start = std::chrono::steady_clock::now();
  int passes = 0;
  while (passes < 3 || (seconds_since(start) < seconds && passes < 50)) {
    const auto t0 = std::chrono::steady_clock::now();
    double* __restrict px = x.data();
    const double* __restrict py = y.data();
    for (std::size_t i = 0; i < n; ++i) px[i] = 0.999 * px[i] + 0.001 * py[i];
    const double t = seconds_since(t0);
    best = std::max(best, 24.0 * d(n) / t);  // 2 reads + 1 write of 8 bytes
    ++passes;
  }
  // Keep the result observable so the passes are not optimised away.
  volatile double sink = x[n / 2];
  (void)sink;
  r.bytes_per_s = best;
  return r;
}

double measure_rotation_step_ns(double seconds) {
  constexpr long kSteps = 2'000'000;
  double best = 1e30;
  const auto start = std::chrono::steady_clock::now();
  int runs = 0;
  volatile double seed = 0.7;
  volatile double forgotten_seed = 0.999, square_seed = 0.5;
  while (runs < 3 || (seconds_since(start) < seconds && runs < 20)) {
    // The weight's chain in givens::rotate_sqrt_free: w' = (w f) / (f + w x^2)
    // as a multiply-add, a division and a product.
    double w = seed;
    const double forgotten = forgotten_seed, xx = square_seed;
    const auto t0 = std::chrono::steady_clock::now();
    for (long k = 0; k < kSteps; ++k) {
      const double inv = 1.0 / (forgotten + w * xx);
      w = (w * forgotten) * inv;  // decays like 1 / k: no subnormals in 2e6 steps
    }
    const double t = seconds_since(t0);
    volatile double sink = w;
    (void)sink;
    best = std::min(best, 1e9 * t / static_cast<double>(kSteps));
    ++runs;
  }
  return best;
}

}  // namespace mpm::bench
