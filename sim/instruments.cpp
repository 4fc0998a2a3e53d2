#include "sim/instruments.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace mpm::sim {

namespace {

std::string channel(const InputEdit& e) { return "input " + e.input; }
std::string channel(const OutputEdit& e) { return "output " + e.output; }

}  // namespace

void validate(const InputEdit& e) {
  const std::string who = channel(e) + ": ";
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
    throw std::invalid_argument(channel(e) + ": sensor_lag_pole must be in [0, 1)");
}

Actuator::Actuator(const InputEdit& e)
    : lag_pole_(e.actuator_lag_pole),
      lower_(e.lower_limit),
      upper_(e.upper_limit),
      half_width_(0.5 * e.deadband_width) {}

double Actuator::step(double command) noexcept {
  // Backlash: the stem follows only once the command pushes past half the band.
  backlash_out_ = std::clamp(backlash_out_, command - half_width_, command + half_width_);
  lag_out_ = lag_pole_ * lag_out_ + (1.0 - lag_pole_) * backlash_out_;
  return std::clamp(lag_out_, lower_, upper_);
}

template <class Element>
ChannelStage<Element>::ChannelStage(std::size_t n_channels,
                                    const std::vector<std::pair<std::size_t, typename Element::Edit>>& edits)
    : elements_(n_channels) {
  for (const auto& [index, e] : edits) {
    validate(e);
    if (index >= n_channels) throw std::invalid_argument(channel(e) + ": index out of range");
    elements_[index] = Element(e);
  }
}

template class ChannelStage<Actuator>;  // declared extern in the header
template class ChannelStage<Sensor>;

}  // namespace mpm::sim
