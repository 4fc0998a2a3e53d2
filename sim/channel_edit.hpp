// How one channel of the plant differs from the nominal model channel: the
// mismatch physics of formats.md expressed as edits of a transfer function.
#pragma once

#include <optional>
#include <string>

#include "core/plant_model.hpp"
#include "core/transfer_function.hpp"

namespace mpm::sim {

// Edits are applied in this order: replacement (or the nominal channel),
// continuous-time edits (time constant, integrator; re-discretised by ZOH when
// the channel has a continuous form), then discrete edits (gain, pole, extra
// lag, extra delay). A default-constructed edit changes nothing.
struct ChannelEdit {
  std::string output;  // names as in the plant file
  std::string input;

  double gain_factor = 1.0;           // G_P = k G_M (steady-state gain x k)
  double pole_factor = 1.0;           // every discrete pole x f; the gain moves too (paper's G12 edit)
  double time_constant_factor = 1.0;  // every time constant x f, steady-state gain unchanged
  int extra_delay = 0;                // samples of pure delay added (>= 0)
  double extra_lag_pole = 0.0;        // unit-gain (1-p)/(1-p q^-1) in series; 0 = none
  bool add_integrator = false;        // G_P = G_M / s (continuous) or G_M Ts/(1-q^-1)
  // A static map in front of the channel: it acts on v / (1 + a |v|), v its
  // input's deviation from the operating point (a >= 0; 0 = linear). Odd,
  // with local gain 1 / (1 + a |v|)^2: a valve or pump whose effect falls
  // away from the point the model was identified at. Not a transfer
  // function edit: plant_channels() carries it to the process.
  double soft_saturation = 0.0;
  // The plant channel is this instead of the model's (a missing channel, a
  // changed structure); the edits above then apply to it.
  std::optional<ContinuousTf> replace_continuous{};  // {}: an edit may be written {.output, .input, .gain_factor}
  std::optional<DiscreteTf> replace_discrete{};

  bool changes_nothing() const;
};

// The plant's channel for `edit` given the nominal channel (nullptr when the
// model has none: then the edit must replace it). Throws std::invalid_argument
// naming the channel when the edit cannot apply.
DiscreteTf edited_channel(const ChannelModel* nominal, const ChannelEdit& edit, double sample_time);

}  // namespace mpm::sim
