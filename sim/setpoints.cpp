#include "sim/setpoints.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace mpm::sim {
namespace {

void validate(const SetpointSpec& s, std::size_t j) {
  const std::string who = "setpoint of output " + std::to_string(j + 1) + ": ";
  for (std::size_t i = 1; i < s.steps.size(); ++i)
    if (s.steps[i].first <= s.steps[i - 1].first) throw std::invalid_argument(who + "steps must be in time order");
  if (s.random_amplitude < 0.0) throw std::invalid_argument(who + "random_amplitude must be >= 0");
  if (s.random_amplitude > 0.0 && (s.random_period_min < 1 || s.random_period_max < s.random_period_min))
    throw std::invalid_argument(who + "random periods must satisfy 1 <= min <= max");
  if (!(s.zone_lower <= s.zone_upper)) throw std::invalid_argument(who + "zone_lower must not exceed zone_upper");
}

}  // namespace

SetpointGenerator::SetpointGenerator(std::vector<SetpointSpec> specs, double sample_time, std::uint64_t seed)
    : specs_(std::move(specs)), state_(specs_.size()), sample_time_(sample_time) {
  std::seed_seq seq{static_cast<std::uint32_t>(seed), static_cast<std::uint32_t>(seed >> 32), 0x5e7901u};
  engine_.seed(seq);
  for (std::size_t j = 0; j < specs_.size(); ++j) {
    validate(specs_[j], j);
    state_[j].level = specs_[j].initial;
    if (specs_[j].random_amplitude > 0.0) state_[j].next_random = draw_period(specs_[j]);
  }
}

long SetpointGenerator::draw_period(const SetpointSpec& s) noexcept {
  std::uniform_int_distribution<long> period(s.random_period_min, s.random_period_max);
  return period(engine_);
}

void SetpointGenerator::at(long k, double* r) noexcept {
  for (std::size_t j = 0; j < specs_.size(); ++j) {
    const SetpointSpec& s = specs_[j];
    State& st = state_[j];
    while (st.next_step < s.steps.size() && s.steps[st.next_step].first <= k) st.level = s.steps[st.next_step++].second;
    if (s.random_amplitude > 0.0 && k >= st.next_random) {
      std::uniform_real_distribution<double> jump(-s.random_amplitude, s.random_amplitude);
      st.level = s.initial + jump(engine_);
      st.next_random = k + draw_period(s);
    }
    const double sine = s.sine_amplitude * std::sin(s.sine_frequency * static_cast<double>(k) * sample_time_);
    r[j] = std::clamp(st.level + sine, s.zone_lower, s.zone_upper);
  }
}

}  // namespace mpm::sim
