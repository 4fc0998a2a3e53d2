// Named closed-loop scenarios: which plant file, how the plant differs from
// it, the MPC tuning, setpoints and noise. `mpm simulate --list` prints them.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "core/plant_model.hpp"
#include "sim/closed_loop.hpp"

namespace mpm::sim {

struct Scenario {
  std::string name;
  std::string summary;     // one line for --list
  std::string plant_file;  // default plant file under config/; empty: the plant must be given
  LoopConfig loop;
  // Set when the loop is derived from the plant model at run time (`loop` is
  // then unused): the scenario fits any plant file.
  LoopConfig (*tune)(const PlantModel&) = nullptr;
};

const std::vector<Scenario>& scenarios();
// nullptr if there is no scenario of that name.
const Scenario* find_scenario(std::string_view name);

// The scenario's loop on this plant: `loop`, or what `tune` derives from the
// model. Run a scenario chosen by name with this, not with `loop`.
LoopConfig scenario_loop(const Scenario& scenario, const PlantModel& model);

struct ResolvedPlant {
  PlantModel model;
  std::string source;  // the file read, or "built-in <file>"
};

// The scenario's default plant: config/<plant_file> from the first directory
// that has it among $MPM_CONFIG_DIR, the source tree's config/ and the
// installed share/mpm/config/ (when the build defines them), else the copy
// built into the binary. Throws config::ConfigError for an invalid file, or
// for a scenario without a default plant file.
ResolvedPlant default_plant(const Scenario& scenario);

// Directories searched for plant files, in order (for messages and docs).
std::vector<std::string> plant_search_path();

}  // namespace mpm::sim
