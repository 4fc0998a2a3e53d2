// Monte Carlo of the live alarm path under "no mismatch": the plant's own
// closed loop (sim scenario plant-nominal: MPC tuned from the model, plant =
// model), its residual, the monitor as mpmd runs it. Used by
// `mpm calibrate` (refits the detector's thresholds for a plant) and by the
// false-alarm calibration test and script.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "core/granger_monitor.hpp"
#include "core/plant_model.hpp"

namespace mpm {

struct NullRun {
  std::size_t samples = 0;                 // samples the monitor saw (after the transient)
  std::vector<std::size_t> raises;         // monitored-sample index of each raise
  std::vector<std::size_t> raised_outputs; // the output of each raise
  std::vector<std::size_t> raised_inputs;  // the channel it named (n_inputs: none)
  // excursions[k][l]: excursions of window k's statistic above levels[k][l],
  // summed over outputs (an excursion ends below d + (level - d) / 2).
  std::vector<std::vector<std::size_t>> excursions;
};

// One run of `samples` samples with `seed`. `levels` (per window, any
// number each) may be empty. Throws std::invalid_argument when the plant
// cannot be simulated.
// `scenario`: another sim scenario's loop on this plant (e.g. a mismatch
// case, to see it raised the same way).
NullRun null_alarm_run(const PlantModel& plant, const MonitorSettings& settings, std::uint64_t seed,
                       std::size_t samples, const std::vector<std::vector<double>>& levels = {},
                       const std::string& scenario = "plant-nominal");

// Per-window thresholds for a stated rate from observed excursion rates:
// window k's constant c_k = observed / crossing_rate(level, c = 1), taken at
// its highest level with at least `min_count` excursions (else the default
// constant), then h_k solves the crossing-rate formula with c_k.
struct Calibration {
  std::vector<double> constants;
  std::vector<double> thresholds;
  std::vector<std::size_t> counts;         // excursions behind each constant
};
Calibration fit_thresholds(const GrangerMonitor& shape, const std::vector<std::vector<double>>& levels,
                           const std::vector<std::vector<std::size_t>>& excursions, double output_samples,
                           std::size_t min_count);

}  // namespace mpm
