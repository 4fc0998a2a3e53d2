// Built-in copies of the example plant files, so that `mpm simulate` works
// without the source tree or an installed share directory.
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace mpm::sim {

// The text of config/<file_name> as shipped (wood-berry.yaml,
// quad-tank.yaml, quad-tank-4x4.yaml), or nullopt for another name.
std::optional<std::string_view> builtin_plant_text(std::string_view file_name);

}  // namespace mpm::sim
