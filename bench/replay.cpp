#include "bench/replay.hpp"

#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench/alloc_hook.hpp"
#include "bench/cpu_clock.hpp"
#include "bench/workload.hpp"
#include "config/plant_loader.hpp"
#include "core/granger_monitor.hpp"
#include "core/mimo_model.hpp"
#include "core/noise_filter.hpp"
#include "sim/builtin_plants.hpp"

namespace mpm::bench {
namespace {

PlantModel wood_berry() {
  const auto text = sim::builtin_plant_text("wood-berry.yaml");
  if (!text) throw std::runtime_error("built-in wood-berry.yaml missing");
  return config::parse_plant(std::string(*text), "wood-berry.yaml (built in)");
}

// samples x (inputs + outputs), one sample contiguous: u then y.
std::vector<double> record(const PlantModel& plant, std::size_t samples) {
  const std::size_t m = plant.n_inputs();
  const std::size_t n = plant.n_outputs();
  MimoModel process(plant);
  std::vector<DiscreteFilter> noise;
  for (const auto& nm : plant.noise) noise.emplace_back(nm ? nm->tf : DiscreteTf{{1.0}, {1.0}, 0});
  std::mt19937_64 rng(7);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<double> data(samples * (m + n));
  std::vector<double> y(n);
  for (std::size_t k = 0; k < samples; ++k) {
    double* u = data.data() + k * (m + n);
    for (std::size_t i = 0; i < m; ++i) u[i] = normal(rng);
    process.step(u, y.data());
    for (std::size_t j = 0; j < n; ++j) u[m + j] = y[j] + 0.1 * noise[j].step(normal(rng));
  }
  return data;
}

std::vector<std::optional<std::vector<double>>> noise_ar(const PlantModel& plant, int order) {
  std::vector<std::optional<std::vector<double>>> out;
  for (const auto& nm : plant.noise) {
    if (nm) out.emplace_back(inverse_noise_ar_coefficients(nm->tf, order));
    else out.emplace_back(std::nullopt);
  }
  return out;
}

}  // namespace

ReplayResult measure_replay(std::size_t samples) {
  const PlantModel plant = wood_berry();
  const std::size_t m = plant.n_inputs();
  const std::size_t n = plant.n_outputs();
  const std::vector<double> data = record(plant, samples);

  const MonitorSettings settings = paper_settings();
  ResidualGenerator residuals(plant, std::vector<double>(m, 0.0));
  GrangerMonitor monitor(m, n, settings, noise_ar(plant, settings.ar_order));
  std::vector<double> d(n);

  ReplayResult r;
  r.samples = samples;
  AllocationScope scope;
  const double start = thread_cpu_seconds();
  for (std::size_t k = 0; k < samples; ++k) {
    const double* u = data.data() + k * (m + n);
    residuals.step(u, u + m, d.data());
    monitor.update(u, d.data());
  }
  const double seconds = thread_cpu_seconds() - start;
  r.allocations = scope.count();
  r.samples_per_s = static_cast<double>(samples) / seconds;
  return r;
}

}  // namespace mpm::bench
