// Loading the plant description (YAML) and recordings (CSV) of formats.md.
// I/O and parsing live here, never in core/. Every error names the file, the
// line (1-based) or key, and what was expected.
#pragma once

#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "config/limits.hpp"
#include "core/plant_model.hpp"

namespace mpm::config {

// Thrown for any invalid file; what() is the complete user-facing message,
// e.g. "plant.yaml:12:5: model[2].den: expected a list of numbers".
struct ConfigError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Parses and validates a plant file: names unique, channels refer to declared
// inputs/outputs (no duplicates), den[0] != 0, continuous channels proper and
// discretised by ZOH, noise N invertible and stable with a stable inverse,
// sample_time > 0, operating_point sizes match.
// Dimensions, polynomial lengths, delays and the file size are capped by
// `limits` (limits.hpp), each with a located error.
PlantModel load_plant(const std::string& path, const Limits& limits = {});
PlantModel parse_plant(const std::string& yaml_text, const std::string& source_name,
                       const Limits& limits = {});

// A CSV recording: header names and a samples x columns matrix (NaN = missing).
struct Recording {
  std::string source;
  std::vector<std::string> names;
  Eigen::MatrixXd data;
  std::optional<std::size_t> find(const std::string& name) const;
  std::size_t samples() const { return static_cast<std::size_t>(data.rows()); }
};
// The header's column count and the file size are capped by `limits`.
Recording load_recording(const std::string& path, const Limits& limits = {});
Recording parse_recording(const std::string& csv_text, const std::string& source_name,
                          const Limits& limits = {});
void write_recording(const std::string& path, const Recording& rec);

// Column indices of a recording matched to a plant.
struct BoundRecording {
  std::size_t time;                               // "t"
  std::vector<std::size_t> inputs;                // per plant input
  std::vector<std::size_t> outputs;               // per plant output
  std::vector<std::optional<std::size_t>> sim;    // sim_<output>
  std::vector<std::optional<std::size_t>> setpoints;  // r_<output>
  std::vector<std::size_t> extra;                 // any other column
};
// Throws ConfigError if t, an input or an output column is missing, or t is
// not strictly increasing with step sample_time (relative tolerance 1e-6).
BoundRecording bind(const PlantModel& plant, const Recording& rec);

}  // namespace mpm::config
