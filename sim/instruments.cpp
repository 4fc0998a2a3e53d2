#include "sim/instruments.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace mpm::sim {

void validate(const InputEdit& e) {
  const std::string who = "input " + e.input + ": ";
  if (!(e.actuator_lag_pole >= 0.0 && e.actuator_lag_pole < 1.0))
    throw std::invalid_argument(who + "actuator_lag_pole must be in [0, 1)");
  if (std::isnan(e.lower_limit) || std::isnan(e.upper_limit) || !(e.lower_limit < e.upper_limit))
    throw std::invalid_argument(who + "lower_limit must be below upper_limit");
  if (!(e.lower_limit <= 0.0 && e.upper_limit >= 0.0))
    throw std::invalid_argument(who + "the limits must contain the operating point (0 in deviation units)");
  if (!(e.deadband_width >= 0.0) || !std::isfinite(e.deadband_width))
    throw std::invalid_argument(who + "deadband_width must be >= 0");
}

void validate(const OutputEdit& e) {
  if (!(e.sensor_lag_pole >= 0.0 && e.sensor_lag_pole < 1.0))
    throw std::invalid_argument("output " + e.output + ": sensor_lag_pole must be in [0, 1)");
}

InputStage::InputStage(std::size_t n_inputs, const std::vector<std::pair<std::size_t, InputEdit>>& edits)
    : actuators_(n_inputs) {
  for (const auto& [index, e] : edits) {
    validate(e);
    if (index >= n_inputs) throw std::invalid_argument("input " + e.input + ": index out of range");
    Actuator& a = actuators_[index];
    a.lag_pole = e.actuator_lag_pole;
    a.lower = e.lower_limit;
    a.upper = e.upper_limit;
    a.half_width = 0.5 * e.deadband_width;
  }
}

void InputStage::apply(const double* command, double* effective) noexcept {
  for (std::size_t i = 0; i < actuators_.size(); ++i) {
    Actuator& a = actuators_[i];
    // Backlash: the stem follows only once the command pushes past half the band.
    a.backlash_out = std::clamp(a.backlash_out, command[i] - a.half_width, command[i] + a.half_width);
    a.lag_out = a.lag_pole * a.lag_out + (1.0 - a.lag_pole) * a.backlash_out;
    effective[i] = std::clamp(a.lag_out, a.lower, a.upper);
  }
}

void InputStage::reset() noexcept {
  for (Actuator& a : actuators_) a.backlash_out = a.lag_out = 0.0;
}

OutputStage::OutputStage(std::size_t n_outputs, const std::vector<std::pair<std::size_t, OutputEdit>>& edits)
    : lag_pole_(n_outputs, 0.0), state_(n_outputs, 0.0) {
  for (const auto& [index, e] : edits) {
    validate(e);
    if (index >= n_outputs) throw std::invalid_argument("output " + e.output + ": index out of range");
    lag_pole_[index] = e.sensor_lag_pole;
  }
}

void OutputStage::apply(const double* value, double* measured) noexcept {
  for (std::size_t j = 0; j < state_.size(); ++j) {
    state_[j] = lag_pole_[j] * state_[j] + (1.0 - lag_pole_[j]) * value[j];
    measured[j] = state_[j];
  }
}

void OutputStage::reset() noexcept { std::fill(state_.begin(), state_.end(), 0.0); }

}  // namespace mpm::sim
