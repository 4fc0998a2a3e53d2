// Actuators and sensors between the controller and the process: the
// mismatches that act on a whole column (one input) or row (one output) of
// the plant.
#pragma once

#include <cstddef>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace mpm::sim {

// One input's actuator, in deviation units. The command passes through the
// backlash (deadband), then the actuator lag, then the mechanical stops.
struct InputEdit {
  std::string input;                 // name as in the plant file
  double actuator_lag_pole = 0.0;    // unit-gain (1-p)/(1-p q^-1); 0 = ideal actuator
  double lower_limit = -std::numeric_limits<double>::infinity();  // the actuator stops here
  double upper_limit = std::numeric_limits<double>::infinity();
  double deadband_width = 0.0;       // backlash: total width; moves inside it do nothing
};

// One output's transmitter: a unit-gain lag on process output + disturbance.
struct OutputEdit {
  std::string output;
  double sensor_lag_pole = 0.0;
};

// Throws std::invalid_argument naming the input/output for values out of range.
void validate(const InputEdit& e);
void validate(const OutputEdit& e);

class InputStage {
 public:
  InputStage() = default;
  // edits: (input index, edit); inputs without an edit pass through unchanged.
  InputStage(std::size_t n_inputs, const std::vector<std::pair<std::size_t, InputEdit>>& edits);

  // Real-time safe. command -> effective input of the process.
  void apply(const double* command, double* effective) noexcept;
  void reset() noexcept;
  std::size_t size() const noexcept { return actuators_.size(); }

 private:
  struct Actuator {
    double lag_pole = 0.0;
    double lower = -std::numeric_limits<double>::infinity();
    double upper = std::numeric_limits<double>::infinity();
    double half_width = 0.0;
    double backlash_out = 0.0;  // state: where the backlash left the stem
    double lag_out = 0.0;       // state: actuator lag output
  };
  std::vector<Actuator> actuators_;
};

class OutputStage {
 public:
  OutputStage() = default;
  OutputStage(std::size_t n_outputs, const std::vector<std::pair<std::size_t, OutputEdit>>& edits);

  // Real-time safe. process output + disturbance -> measured output.
  void apply(const double* value, double* measured) noexcept;
  void reset() noexcept;
  std::size_t size() const noexcept { return state_.size(); }

 private:
  std::vector<double> lag_pole_;
  std::vector<double> state_;
};

}  // namespace mpm::sim
