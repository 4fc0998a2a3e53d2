#include "bench/workload.hpp"

#include <random>

#include "core/noise_filter.hpp"

namespace mpm::bench {

Workload make_workload(std::size_t inputs, std::size_t outputs, std::size_t samples, std::uint64_t seed) {
  Workload w;
  w.inputs = inputs;
  w.outputs = outputs;
  w.samples = samples;
  w.u.resize(samples * inputs);
  w.residual.resize(samples * outputs);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (double& x : w.u) x = normal(rng);
  constexpr std::size_t kDelay = 3;
  for (std::size_t j = 0; j < outputs; ++j) {
    double d = 0.0;
    for (std::size_t k = 0; k < samples; ++k) {
      const double planted = k >= kDelay ? 0.3 * w.u[(k - kDelay) * inputs + j % inputs] : 0.0;
      d = 0.8 * d + normal(rng);
      w.residual[k * outputs + j] = d + planted;
    }
  }
  return w;
}

MonitorSettings paper_settings() { return {.ar_order = 20, .input_order = 10, .forgetting = 0.999}; }

std::vector<std::optional<std::vector<double>>> ar1_noise_models(std::size_t outputs, int ar_order) {
  DiscreteTf n;
  n.num = {1.0};
  n.den = {1.0, -0.8};
  const std::vector<double> g = inverse_noise_ar_coefficients(n, ar_order);
  return std::vector<std::optional<std::vector<double>>>(outputs, g);
}

std::unique_ptr<GrangerMonitor> make_monitor(std::size_t inputs, std::size_t outputs) {
  const MonitorSettings s = paper_settings();
  return std::make_unique<GrangerMonitor>(inputs, outputs, s, ar1_noise_models(outputs, s.ar_order));
}

std::size_t warm_up(GrangerMonitor& monitor, const Workload& w, std::size_t cursor) {
  while (monitor.update(w.u_at(cursor), w.residual_at(cursor)) != SampleStatus::kUsed) ++cursor;
  return cursor + 1;
}

}  // namespace mpm::bench
