#include "sim/builtin_plants.hpp"

#include <string_view>
#include <utility>

// config/wood-berry.yaml, config/quad-tank.yaml and config/quad-tank-4x4.yaml
// as the build read them (sim/CMakeLists.txt writes the table), so that a
// binary without the files beside it still has the scenarios' plants.
namespace mpm::sim {
namespace {

constexpr std::pair<std::string_view, std::string_view> kBuiltinPlants[] = {
#include "sim/builtin_plant_texts.inc"
};

}  // namespace

std::optional<std::string_view> builtin_plant_text(std::string_view file_name) {
  for (const auto& [name, text] : kBuiltinPlants)
    if (name == file_name) return text;
  return std::nullopt;
}

}  // namespace mpm::sim
