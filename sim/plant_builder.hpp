// What the simulated plant is, relative to the nominal model, and how to
// build it.
#pragma once

#include <vector>

#include "core/plant_model.hpp"
#include "sim/channel_edit.hpp"
#include "sim/extra_input.hpp"
#include "sim/instruments.hpp"
#include "sim/plant_sim.hpp"
#include "sim/quad_tank.hpp"

namespace mpm::sim {

enum class ProcessKind {
  linear,     // the model's channels with `channels` edits applied
  quad_tank,  // the nonlinear quadruple tank (2 pumps, 2 levels); no channel edits
};

struct PlantSpec {
  ProcessKind kind = ProcessKind::linear;
  QuadTankParams quad_tank;
  std::vector<ChannelEdit> channels;
  std::vector<InputEdit> inputs;
  std::vector<OutputEdit> outputs;
  std::vector<ExtraInputSpec> extra_inputs;  // linear plants only
};

// Throws std::invalid_argument naming the edit or signal that does not fit
// the model.
Plant build_plant(const PlantModel& model, const PlantSpec& spec);

// The plant's own operating point in absolute units (the model's for a linear
// plant, the tanks' steady state for the quadruple tank).
OperatingPoint plant_operating_point(const PlantModel& model, const PlantSpec& spec);

}  // namespace mpm::sim
