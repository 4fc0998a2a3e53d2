// Shared helpers of the simulator tests.
#pragma once

#include <string>
#include <vector>

#include "config/plant_loader.hpp"
#include "core/plant_model.hpp"
#include "sim/plant_builder.hpp"

namespace mpm::sim::testing {

inline PlantModel example_plant(const std::string& file) {
  return config::load_plant(std::string(MPM_SOURCE_DIR) + "/config/" + file);
}

// Response of every output (rows: sample k = 0 .. n-1) to the constant
// inputs u applied from sample 0, no disturbance.
inline std::vector<std::vector<double>> step_response(Plant& plant, const std::vector<double>& u, std::size_t n) {
  std::vector<std::vector<double>> y(n, std::vector<double>(plant.n_outputs()));
  const std::vector<double> zero(plant.n_outputs(), 0.0);
  for (std::size_t k = 0; k < n; ++k) {
    plant.measure(zero.data(), y[k].data());
    plant.apply(u.data(), nullptr);
  }
  return y;
}

inline Plant build(const PlantModel& m, const PlantSpec& spec = {}) { return build_plant(m, spec); }

}  // namespace mpm::sim::testing
