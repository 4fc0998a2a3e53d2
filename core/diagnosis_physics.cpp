#include "core/diagnosis_physics.hpp"

#include <utility>

namespace mpm::diagnosis {
namespace {

// The one place a physics word is spelled.
constexpr std::array<std::pair<Physics, std::string_view>, kAllPhysics.size()> kWords{{
    {Physics::gain, "gain"},
    {Physics::time_constant, "time_constant"},
    {Physics::dead_time, "dead_time"},
    {Physics::unmodeled_dynamics, "unmodeled_dynamics"},
    {Physics::integrator, "integrator"},
    {Physics::missing_channel, "missing_channel"},
    {Physics::actuator_dynamics, "actuator_dynamics"},
    {Physics::saturation, "saturation"},
    {Physics::deadband, "deadband"},
    {Physics::sensor_dynamics, "sensor_dynamics"},
    {Physics::nonlinear_gain, "nonlinear_gain"},
    {Physics::unmodeled_input, "unmodeled_input"},
    {Physics::disturbance_model, "disturbance_model"},
    {Physics::other, "other"},
}};

constexpr bool words_in_order() {
  for (std::size_t k = 0; k < kWords.size(); ++k)
    if (kWords[k].first != kAllPhysics[k] || static_cast<std::size_t>(kAllPhysics[k]) != k) return false;
  return true;
}
static_assert(words_in_order(), "kWords lists every Physics once, in the enumerators' order");

}  // namespace

std::string_view word(Physics p) { return kWords[static_cast<std::size_t>(p)].second; }

std::optional<Physics> physics_from_word(std::string_view w) {
  for (const auto& [p, s] : kWords)
    if (s == w) return p;
  return std::nullopt;
}

}  // namespace mpm::diagnosis
