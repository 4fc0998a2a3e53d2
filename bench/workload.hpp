// Realistic, pre-generated monitor input for the timings: random inputs and
// AR(1) residuals (with a small planted input effect, so the statistics are
// not degenerate), fed cyclically so no generation happens in a timed loop.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "core/granger_monitor.hpp"

namespace mpm::bench {

struct Workload {
  std::size_t inputs = 0;
  std::size_t outputs = 0;
  std::size_t samples = 0;
  std::vector<double> u;         // samples x inputs, one sample contiguous
  std::vector<double> residual;  // samples x outputs

  const double* u_at(std::size_t k) const noexcept { return u.data() + (k % samples) * inputs; }
  const double* residual_at(std::size_t k) const noexcept { return residual.data() + (k % samples) * outputs; }
};

// d_j(k) = 0.8 d_j(k-1) + a_j(k) + 0.3 u_{j mod m}(k-3); u, a ~ N(0, 1).
Workload make_workload(std::size_t inputs, std::size_t outputs, std::size_t samples, std::uint64_t seed = 1);

// The paper's orders (na = 20, nb = 10), plain lags, forgetting 0.999 as mpmd.
MonitorSettings paper_settings();

// AR coefficients of 1 - N^-1 for N = 1 / (1 - 0.8 q^-1), from
// inverse_noise_ar_coefficients, one per output: gamma is computed.
std::vector<std::optional<std::vector<double>>> ar1_noise_models(std::size_t outputs, int ar_order);

// A monitor of the given size with paper_settings() and ar1_noise_models().
std::unique_ptr<GrangerMonitor> make_monitor(std::size_t inputs, std::size_t outputs);

// Feeds samples until the monitor uses them (lags filled); returns the next
// cursor into the workload.
std::size_t warm_up(GrangerMonitor& monitor, const Workload& w, std::size_t cursor);

}  // namespace mpm::bench
