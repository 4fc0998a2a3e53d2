#include "bench/replay.hpp"

#include <algorithm>
#include <chrono>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "tests/support/alloc_counter.hpp"
#include "bench/cpu_clock.hpp"
#include "bench/workload.hpp"
#include "config/plant_loader.hpp"
#include "core/granger_monitor.hpp"
#include "core/mimo_model.hpp"
#include "core/monitor_front_end.hpp"
#include "daemon/offline.hpp"
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


}  // namespace

ReplayResult measure_replay(std::size_t samples) {
  const PlantModel plant = wood_berry();
  const std::size_t m = plant.n_inputs();
  const std::size_t n = plant.n_outputs();
  const std::vector<double> data = record(plant, samples);

  const MonitorSettings settings = paper_settings();
  ResidualGenerator residuals(plant, std::vector<double>(m, 0.0));
  // The paper's monitor of the plant (plain lags), built as every command builds it.
  const MonitorBlueprint blueprint(plant, settings, /*plain_lags=*/true);
  GrangerMonitor monitor = blueprint.build();
  std::vector<double> d(n);

  ReplayResult r;
  r.samples = samples;
  {
    test::AllocationScope scope;
    const double start = thread_cpu_seconds();
    for (std::size_t k = 0; k < samples; ++k) {
      const double* u = data.data() + k * (m + n);
      residuals.step(u, u + m, d.data());
      monitor.update(u, d.data());
    }
    const double seconds = thread_cpu_seconds() - start;
    r.allocations = scope.count();
    r.samples_per_s = static_cast<double>(samples) / seconds;
  }

  // The same replay as `mpm monitor` runs it: residuals first, then the
  // outputs split over threads (run_monitor_parallel), wall-clock time.
  std::vector<double> inputs(samples * m), residual(samples * n);
  for (std::size_t k = 0; k < samples; ++k)
    std::copy(data.data() + k * (m + n), data.data() + k * (m + n) + m, inputs.data() + k * m);
  const auto make = [&](OutputRange outputs) { return blueprint.build(outputs); };
  r.threads = replay_threads(n);
  // Wall-clock time on a shared machine: the other core may be taken for a
  // while by another tenant, so the median of a few runs.
  r.parallel_identical = true;
  for (int run = 0; run < ReplayResult::kParallelRuns; ++run) {
    GrangerMonitor merged = make(OutputRange{});
    ResidualGenerator residuals2(plant, std::vector<double>(m, 0.0));
    const auto wall_start = std::chrono::steady_clock::now();
    for (std::size_t k = 0; k < samples; ++k) {
      const double* u = data.data() + k * (m + n);
      residuals2.step(u, u + m, residual.data() + k * n);
    }
    run_monitor_parallel(merged, inputs.data(), residual.data(), 0, samples, r.threads, make);
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
    r.parallel_runs[run] = static_cast<double>(samples) / wall;
    // The split must not change a single statistic.
    for (std::size_t j = 0; j < n; ++j)
      for (std::size_t i = 0; i < m; ++i)
        r.parallel_identical = r.parallel_identical &&
                               merged.channel(j, i).lr_conditional == monitor.channel(j, i).lr_conditional &&
                               merged.channel(j, i).gamma == monitor.channel(j, i).gamma;
  }
  double sorted[ReplayResult::kParallelRuns];
  std::copy(std::begin(r.parallel_runs), std::end(r.parallel_runs), sorted);
  std::sort(std::begin(sorted), std::end(sorted));
  r.parallel_samples_per_s = sorted[ReplayResult::kParallelRuns / 2];
  return r;
}

}  // namespace mpm::bench
