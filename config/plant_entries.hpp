// Reading one `model:` or `noise:` entry of a plant file. Internal to config/.
#pragma once

#include <cstddef>

#include "config/yaml_reader.hpp"
#include "core/plant_model.hpp"

namespace mpm::config::detail {

// Longest pure delay accepted, in samples: beyond it a typo (a dead time in
// seconds where minutes were meant, say) would silently allocate filter
// histories of gigabytes.
inline constexpr int kMaxDelaySamples = 1'000'000;

// `plant` supplies names and sample_time (already read and checked).
ChannelModel read_channel(const YamlReader& reader, const Field& entry, const PlantModel& plant);

struct NoiseEntry {
  std::size_t output = 0;
  NoiseModel model;
};
NoiseEntry read_noise(const YamlReader& reader, const Field& entry, const PlantModel& plant);

}  // namespace mpm::config::detail
