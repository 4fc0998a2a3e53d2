// `mpm diagnose --write-plant`: the plant file with the diagnosis's accepted
// corrections applied, in the plant YAML of docs/formats.md, each change
// commented with the finding that made it and the held-out improvement that
// justified it. Corrections the plant format cannot express (a saturation, a
// backlash, a level-dependent gain, a recorded signal that drives an output)
// are listed in the header as not applied, so the file never claims more
// than it holds.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "core/diagnosis.hpp"
#include "core/plant_model.hpp"

namespace mpm {

// What became of one finding in the corrected plant file.
enum class Written : std::uint8_t {
  kApplied,
  kNotExpressible,  // the plant format cannot express it
  kImplausible,     // flagged implausible (a heater that cools): held back for a person to judge
};

struct CorrectedPlant {
  PlantModel plant;                        // the corrected model
  std::vector<std::vector<std::string>> why;  // per plant.channels entry: the findings that changed it
  std::vector<std::vector<std::string>> noise_why;  // per output
  std::vector<std::string> not_applied;     // findings the format cannot express
  std::vector<std::string> held_back;       // findings flagged implausible, not applied
  std::vector<Written> written;             // per finding of the result, in its order
  std::size_t changes = 0;                  // channel or noise entries changed
};

// Applies the findings, in the order they were accepted, to `plant`:
// single-channel findings (gain, dead_time, time_constant,
// unmodeled_dynamics, integrator, missing_channel) set that channel to the
// fitted model (a second finding on the same channel is composed with the
// first where its parameters allow: a gain factor, an extra delay, an extra
// lag); actuator / sensor dynamics put the fitted lag in series with every
// channel of that input / output; disturbance_model replaces that output's N.
// A finding flagged implausible is not applied: the file says why.
CorrectedPlant apply_findings(const PlantModel& plant, const diagnosis::Result& result);

// The corrected plant as YAML text. Channels left unchanged keep the
// continuous form when the input file gave it; changed ones are written in
// discrete form unless the change is exact in continuous form too (a gain
// factor, a whole number of samples of dead time).
std::string plant_yaml(const CorrectedPlant& corrected, const std::string& source_plant,
                       const std::string& source_data);

// Writes `text` to `path` through config/output_file.hpp: throws
// config::ConfigError naming the path when `path` is one of
// `protected_paths` (the command's input files are never overwritten) or
// the write fails.
void write_text_file(const std::string& path, const std::string& text,
                     const std::vector<std::string>& protected_paths);

}  // namespace mpm
