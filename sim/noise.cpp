#include "sim/noise.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace mpm::sim {

std::vector<NoiseChannel> noise_channels(const PlantModel& model, double default_variance) {
  std::vector<NoiseChannel> out(model.n_outputs());
  for (std::size_t j = 0; j < out.size(); ++j) {
    out[j].variance = default_variance;
    if (j < model.noise.size() && model.noise[j]) {
      out[j].filter = model.noise[j]->tf;
      if (model.noise[j]->variance) out[j].variance = *model.noise[j]->variance;
    }
  }
  return out;
}

NoiseSource::NoiseSource(const std::vector<NoiseChannel>& channels, std::uint64_t seed, double scale)
    : engine_(seed) {
  if (!(scale >= 0.0) || !std::isfinite(scale)) throw std::invalid_argument("noise scale must be >= 0");
  for (std::size_t j = 0; j < channels.size(); ++j) {
    const NoiseChannel& c = channels[j];
    if (!(c.variance >= 0.0) || !std::isfinite(c.variance))
      throw std::invalid_argument("noise of output " + std::to_string(j + 1) + ": variance must be >= 0");
    if (!c.filter.is_stable())
      throw std::invalid_argument("noise of output " + std::to_string(j + 1) + ": N must be stable");
    stddev_.push_back(scale * std::sqrt(c.variance));
    filters_.emplace_back(c.filter);
  }
}

void NoiseSource::draw(double* d) noexcept {
  // Draw every a_j even when its std is 0, so that one output's noise does not
  // depend on whether another's is switched off.
  for (std::size_t j = 0; j < filters_.size(); ++j) d[j] = filters_[j].step(stddev_[j] * normal_(engine_));
}

}  // namespace mpm::sim
