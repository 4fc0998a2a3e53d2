#include "sim/extra_input.hpp"

#include <cmath>
#include <stdexcept>

namespace mpm::sim {

ExtraInputSource::ExtraInputSource(const std::vector<ExtraInputSpec>& specs, std::uint64_t seed) {
  std::seed_seq seq{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32), 0xe7a1u};
  engine_.seed(seq);
  for (const auto& s : specs) {
    if (!(s.pole >= 0.0 && s.pole < 1.0)) throw std::invalid_argument("extra input " + s.name + ": pole must be in [0, 1)");
    if (!(s.stddev >= 0.0) || !std::isfinite(s.stddev))
      throw std::invalid_argument("extra input " + s.name + ": stddev must be >= 0");
    pole_.push_back(s.pole);
    innovation_std_.push_back(s.stddev * std::sqrt(1.0 - s.pole * s.pole));
    state_.push_back(0.0);
  }
}

void ExtraInputSource::draw(double* x) noexcept {
  for (std::size_t i = 0; i < state_.size(); ++i) {
    state_[i] = pole_[i] * state_[i] + innovation_std_[i] * normal_(engine_);
    x[i] = state_[i];
  }
}

}  // namespace mpm::sim
