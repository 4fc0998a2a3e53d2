#include "sim/plant_builder.hpp"

#include <algorithm>
#include <memory>
#include <stdexcept>
#include <string>

#include "sim/linear_process.hpp"

namespace mpm::sim {
namespace {

// Extra inputs become further process inputs n_inputs, n_inputs+1, ...
void add_extra_channels(const PlantModel& model, const PlantSpec& spec, std::vector<LinearChannel>& channels) {
  for (std::size_t x = 0; x < spec.extra_inputs.size(); ++x) {
    const ExtraInputSpec& e = spec.extra_inputs[x];
    if (std::find(model.inputs.begin(), model.inputs.end(), e.name) != model.inputs.end() ||
        std::find(model.outputs.begin(), model.outputs.end(), e.name) != model.outputs.end())
      throw std::invalid_argument("extra input '" + e.name + "' has the name of a model signal");
    for (const auto& [output, tf] : e.drives)
      channels.push_back({index_of(model.outputs, output, "output"), model.n_inputs() + x,
                          discretize_zoh(tf, model.sample_time)});
  }
}

std::unique_ptr<Process> build_process(const PlantModel& model, const PlantSpec& spec) {
  if (spec.kind == ProcessKind::quad_tank) {
    if (model.n_inputs() != 2 || model.n_outputs() != 2)
      throw std::invalid_argument("the quadruple tank has 2 inputs and 2 outputs; the model has " +
                                  std::to_string(model.n_inputs()) + " and " + std::to_string(model.n_outputs()));
    if (!spec.channels.empty() || !spec.extra_inputs.empty())
      throw std::invalid_argument("the quadruple tank takes no channel edits or extra inputs");
    return std::make_unique<QuadTankProcess>(spec.quad_tank, model.sample_time);
  }
  std::vector<LinearChannel> channels = plant_channels(model, spec.channels);
  add_extra_channels(model, spec, channels);
  return std::make_unique<LinearProcess>(model.n_inputs() + spec.extra_inputs.size(), model.n_outputs(), channels);
}

}  // namespace

Plant build_plant(const PlantModel& model, const PlantSpec& spec) {
  std::vector<std::pair<std::size_t, InputEdit>> inputs;
  for (const auto& e : spec.inputs) inputs.emplace_back(index_of(model.inputs, e.input, "input"), e);
  std::vector<std::pair<std::size_t, OutputEdit>> outputs;
  for (const auto& e : spec.outputs) outputs.emplace_back(index_of(model.outputs, e.output, "output"), e);
  return Plant(build_process(model, spec), model.n_inputs(), InputStage(model.n_inputs(), inputs),
               OutputStage(model.n_outputs(), outputs));
}

OperatingPoint plant_operating_point(const PlantModel& model, const PlantSpec& spec) {
  if (spec.kind == ProcessKind::quad_tank) {
    const QuadTankParams& p = spec.quad_tank;
    const auto h = steady_levels(p, p.pump_voltage);
    return {{p.pump_voltage[0], p.pump_voltage[1]}, {p.sensor_gain * h[0], p.sensor_gain * h[1]}};
  }
  if (model.operating_point) return *model.operating_point;
  return {std::vector<double>(model.n_inputs(), 0.0), std::vector<double>(model.n_outputs(), 0.0)};
}

}  // namespace mpm::sim
