#include "core/plant_model.hpp"

namespace mpm {

const ChannelModel* PlantModel::channel(std::size_t output, std::size_t input) const {
  for (const auto& c : channels)
    if (c.output == output && c.input == input) return &c;
  return nullptr;
}

}  // namespace mpm
