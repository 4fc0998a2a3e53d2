// Plant edits written as text, for `mpm simulate --edit SPEC`:
//
//   OUTPUT.INPUT.KEY=VALUE  a channel edit (ChannelEdit):  gain, pole,
//                           time_constant, delay, lag, integrator
//   INPUT.KEY=VALUE         an actuator edit (InputEdit):  actuator_lag,
//                           lower, upper, deadband
//   OUTPUT.KEY=VALUE        a transmitter edit (OutputEdit): sensor_lag
//
// parse_edit() reads and checks one spec against the plant's signal names;
// apply_edits() folds a list of them into a PlantSpec. Kept apart from the
// command so that both can be tested without running a loop. Every error is
// a std::invalid_argument whose message starts with the spec in quotes.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "sim/plant_builder.hpp"

namespace mpm::sim {

// The field of ChannelEdit / InputEdit / OutputEdit a spec sets.
enum class EditField {
  gain,           // ChannelEdit::gain_factor, any finite number
  pole,           // ChannelEdit::pole_factor, > 0
  time_constant,  // ChannelEdit::time_constant_factor, > 0
  delay,          // ChannelEdit::extra_delay, whole samples 0..kMaxEditDelay
  lag,            // ChannelEdit::extra_lag_pole, in [0, 1)
  integrator,     // ChannelEdit::add_integrator, 0 or 1 (no value: 1)
  soft_saturation,  // ChannelEdit::soft_saturation, >= 0
  actuator_lag,   // InputEdit::actuator_lag_pole, in [0, 1)
  lower,          // InputEdit::lower_limit, <= 0 (deviation from the operating point)
  upper,          // InputEdit::upper_limit, >= 0
  deadband,       // InputEdit::deadband_width, >= 0
  sensor_lag,     // OutputEdit::sensor_lag_pole, in [0, 1)
};

enum class EditTarget { channel, input, output };

// The extra delay allowed on one channel, in samples (each costs a buffer slot).
inline constexpr int kMaxEditDelay = 10000;

struct EditSpec {
  std::string text;    // as given, for messages
  EditField field = EditField::gain;
  std::string output;  // channel and output edits (a plant file name)
  std::string input;   // channel and input edits
  double value = 0.0;  // checked against the field's range
};

EditTarget target_of(EditField field);

// Throws std::invalid_argument for a malformed spec, an unknown name or key,
// a missing, non-finite or out-of-range value.
EditSpec parse_edit(std::string_view text, const std::vector<std::string>& inputs,
                    const std::vector<std::string>& outputs);

// Sets each spec's field on the plant's edit of its channel, input or output,
// adding that edit when the plant has none: keys the specs do not give keep
// the plant's (the scenario's) values, keys they give replace them. Throws
// std::invalid_argument (and leaves `plant` unspecified) when a key is given
// twice for the same target, for channel edits of the nonlinear quadruple
// tank, and for input limits that do not contain the operating point.
void apply_edits(const std::vector<EditSpec>& specs, PlantSpec& plant);

// "y2.u1.gain=1.5, u2.actuator_lag=0.45": the specs as given.
std::string describe(const std::vector<EditSpec>& specs);

}  // namespace mpm::sim
