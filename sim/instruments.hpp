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

// One input's actuator (InputEdit); default: ideal, the command passes.
class Actuator {
 public:
  using Edit = InputEdit;
  Actuator() = default;
  explicit Actuator(const InputEdit& e);

  double step(double command) noexcept;  // command -> effective input
  void reset() noexcept { backlash_out_ = lag_out_ = 0.0; }

 private:
  double lag_pole_ = 0.0;
  double lower_ = -std::numeric_limits<double>::infinity();
  double upper_ = std::numeric_limits<double>::infinity();
  double half_width_ = 0.0;
  double backlash_out_ = 0.0;  // state: where the backlash left the stem
  double lag_out_ = 0.0;       // state: actuator lag output
};

// One output's transmitter (OutputEdit); default: ideal, the value passes.
class Sensor {
 public:
  using Edit = OutputEdit;
  Sensor() = default;
  explicit Sensor(const OutputEdit& e) : lag_pole_(e.sensor_lag_pole) {}

  double step(double value) noexcept {  // process output + disturbance -> measured
    state_ = lag_pole_ * state_ + (1.0 - lag_pole_) * value;
    return state_;
  }
  void reset() noexcept { state_ = 0.0; }

 private:
  double lag_pole_ = 0.0;
  double state_ = 0.0;
};

// One Element (Actuator or Sensor) per channel, stepped and reset together.
template <class Element>
class ChannelStage {
 public:
  ChannelStage() = default;
  // edits: (channel index, edit); channels without an edit pass through
  // unchanged. Throws std::invalid_argument for a bad edit or index.
  ChannelStage(std::size_t n_channels, const std::vector<std::pair<std::size_t, typename Element::Edit>>& edits);

  // Real-time safe.
  void apply(const double* in, double* out) noexcept {
    for (std::size_t i = 0; i < elements_.size(); ++i) out[i] = elements_[i].step(in[i]);
  }
  void reset() noexcept {
    for (Element& e : elements_) e.reset();
  }
  std::size_t size() const noexcept { return elements_.size(); }

 private:
  std::vector<Element> elements_;
};

// Instantiated once, in instruments.cpp, where the constructor is.
extern template class ChannelStage<Actuator>;
extern template class ChannelStage<Sensor>;

using InputStage = ChannelStage<Actuator>;  // command -> effective input of the process
using OutputStage = ChannelStage<Sensor>;   // process output + disturbance -> measured output

}  // namespace mpm::sim
