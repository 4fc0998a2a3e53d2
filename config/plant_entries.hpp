// Reading one `model:` or `noise:` entry of a plant file. Internal to config/.
#pragma once

#include <cstddef>

#include "config/limits.hpp"
#include "config/yaml_reader.hpp"
#include "core/plant_model.hpp"

namespace mpm::config::detail {

// `plant` supplies names and sample_time (already read and checked); `limits`
// caps polynomial lengths and delays (errors name the key and the range).
ChannelModel read_channel(const YamlReader& reader, const Field& entry, const PlantModel& plant,
                          const Limits& limits);

struct NoiseEntry {
  std::size_t output = 0;
  NoiseModel model;
};
// A channel's model must be stable or integrating (the IMC residual of an
// unstable one grows without bound); the error is placed at `at`.
void check_model_stable(const YamlReader& reader, const Field& at, const DiscreteTf& tf);

// `state_space:` (formats.md 4.5) into plant.channels, and plant.noise when
// it has a disturbance model; plant's names and sample_time already read.
void read_state_space(const YamlReader& reader, const Field& field, const Limits& limits, PlantModel& plant);

NoiseEntry read_noise(const YamlReader& reader, const Field& entry, const PlantModel& plant,
                      const Limits& limits);

}  // namespace mpm::config::detail
