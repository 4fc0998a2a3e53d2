// The plant description of formats.md as plain data: what the controller's
// model G_M and the disturbance model N are. Loading it from YAML lives in
// config/; this header has no I/O.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/transfer_function.hpp"

namespace mpm {

struct ChannelModel {
  std::size_t output = 0;  // index into PlantModel::outputs
  std::size_t input = 0;   // index into PlantModel::inputs
  DiscreteTf tf;           // already discretised at sample_time
  bool explicit_zero = false;  // present in the file with num: [0]
  // Set when the file gave the continuous form (kept for reports).
  std::optional<ContinuousTf> continuous;
};

// Disturbance model N of one output: d = N a, a white with `variance`.
struct NoiseModel {
  DiscreteTf tf;             // delay must be 0, num[0] != 0 (invertible)
  std::optional<double> variance;
};

struct OperatingPoint {
  std::vector<double> inputs;
  std::vector<double> outputs;
};

struct PlantModel {
  std::string name;
  double sample_time = 1.0;
  std::vector<std::string> inputs;
  std::vector<std::string> outputs;
  std::vector<ChannelModel> channels;          // absent channel = zero gain
  std::vector<std::optional<NoiseModel>> noise;  // one per output; nullopt = unknown N
  std::optional<OperatingPoint> operating_point;

  std::size_t n_inputs() const { return inputs.size(); }
  std::size_t n_outputs() const { return outputs.size(); }
  // Channel for (output, input), or nullptr when the model has none.
  const ChannelModel* channel(std::size_t output, std::size_t input) const;
};

}  // namespace mpm
