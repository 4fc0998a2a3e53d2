// What `--data` names: a CSV recording (formats.md section 2) or an
// lcm-logger file of the sample channel (formats.md section 4.4), told apart by the
// file's first bytes (LCM's sync word), never by its name.
#pragma once

#include <memory>
#include <string>

#include "config/plant_loader.hpp"
#include "config/row_source.hpp"

namespace mpm {

struct DataOptions {
  std::string lcm_channel = "MPM_SAMPLE";  // --channel: the sample channel of an LCM log
  // Where the reader's notes go (what an LCM log's reader skipped), e.g.
  // "mpm diagnose"; empty: not printed.
  std::string report_as;
  config::Limits limits;  // caps on a CSV's size and columns (--max-... flags)
};

// The whole recording. Throws ConfigError naming the file (and line or event).
config::Recording load_data(const std::string& path, const PlantModel& plant, const DataOptions& options);

// The same rows one at a time (the streaming monitor); its notes() say what
// an LCM log's reader skipped.
std::unique_ptr<config::RowSource> open_data(const std::string& path, const PlantModel& plant,
                                             const DataOptions& options);

// Prints a reader's notes as `report_as: notes` on standard error, if any.
void report_notes(const config::RowSource& source, const DataOptions& options);

}  // namespace mpm
