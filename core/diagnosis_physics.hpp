// The physics words of the diagnosis (formats.md section 3): one enumerator
// per word, and the one table that spells them (diagnosis_physics.cpp).
// Everything that writes or reads a word (the findings, the JSON, the plant
// writer, the daemon's messages) takes it from here.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <string_view>

namespace mpm::diagnosis {

enum class Physics {
  gain,
  time_constant,
  dead_time,
  unmodeled_dynamics,  // an extra lag on one channel
  integrator,
  missing_channel,
  actuator_dynamics,
  saturation,
  deadband,
  sensor_dynamics,
  nonlinear_gain,
  unmodeled_input,    // a recorded signal the model leaves out
  disturbance_model,  // a changed noise model
  other,              // the monitor locates a mismatch no hypothesis explains
};

// Every word, in the enumerators' order.
inline constexpr std::array<Physics, 14> kAllPhysics{
    Physics::gain,           Physics::time_constant,     Physics::dead_time,       Physics::unmodeled_dynamics,
    Physics::integrator,     Physics::missing_channel,   Physics::actuator_dynamics, Physics::saturation,
    Physics::deadband,       Physics::sensor_dynamics,   Physics::nonlinear_gain,  Physics::unmodeled_input,
    Physics::disturbance_model, Physics::other};

// The word as written in the diagnosis JSON ("gain", "dead_time", ...).
std::string_view word(Physics p);
// The physics a word names; nullopt for anything else.
std::optional<Physics> physics_from_word(std::string_view w);

}  // namespace mpm::diagnosis
