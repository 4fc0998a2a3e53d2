// Step responses of a model's channels, long enough to have settled: the
// dynamic-matrix (DMC) description the controller predicts with.
#pragma once

#include <cstddef>
#include <vector>

#include <Eigen/Dense>

#include "core/plant_model.hpp"

namespace mpm::sim {

class StepResponses {
 public:
  StepResponses() = default;
  // Simulates each channel's response to a unit step at sample 0 and keeps
  // the shortest length >= min_length after which every stable channel is at
  // its steady-state gain, and every integrating one ramps with a constant
  // slope, to within `tolerance` times its largest value. Throws
  // std::invalid_argument if a channel has not settled by max_length
  // (an unstable model).
  StepResponses(const PlantModel& model, std::size_t min_length, double tolerance, std::size_t max_length);

  std::size_t length() const noexcept { return static_cast<std::size_t>(s_.cols()); }
  // Response of output j to a unit step on input l, n samples after the step;
  // beyond length() a stable channel holds its gain, an integrating one keeps
  // its slope. Real-time safe.
  double at(std::size_t j, std::size_t l, std::size_t n) const noexcept;
  // True if some channel into output j integrates (its step response ramps).
  bool ramps(std::size_t j) const noexcept { return ramps_[j]; }

 private:
  std::size_t n_inputs_ = 0;
  Eigen::MatrixXd s_;           // row j * n_inputs + l, column n
  Eigen::VectorXd slope_;       // per row: 0 for stable channels
  std::vector<bool> ramps_;     // per output
};

}  // namespace mpm::sim
