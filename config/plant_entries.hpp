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
NoiseEntry read_noise(const YamlReader& reader, const Field& entry, const PlantModel& plant,
                      const Limits& limits);

}  // namespace mpm::config::detail
