// Caps on what a loaded file may ask for. A plant or recording is untrusted
// input: without a cap, one typo (a 2000 x 2000 plant, a dead time in seconds
// where minutes were meant, a CSV header of a million columns) makes a loader
// or a later setup step allocate gigabytes or run for minutes. Every cap is
// checked while loading, and its error names the file, line:column, key and
// the allowed range. The defaults cover every plant in the tree with a wide
// margin; a caller with a bigger plant passes its own Limits, set from the
// daemon config's `limits:` section or the `--max-...` flags of mpm
// (Limits::fields(): one row per cap, read by both).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "core/field_table.hpp"

namespace mpm::config {

struct Limits {
  std::size_t max_inputs = 100;            // plant inputs (manipulated variables)
  std::size_t max_outputs = 100;           // plant outputs (controlled variables)
  std::size_t max_poly_length = 200;       // coefficients in one num or den
  int max_delay_samples = 1000;            // pure delay of one channel, in samples
  std::size_t max_states = 50;             // states of a state_space plant (its channels' order)
  std::uint64_t max_yaml_bytes = 64u << 20;  // a plant or daemon config file
  std::size_t max_csv_columns = 10000;     // columns of a recording's header
  std::uint64_t max_csv_bytes = std::uint64_t{16} << 30;  // a whole recording read at once

  // One row per cap: its key (the daemon config's `limits:` key; the mpm
  // flag is "--" + key with '-' for '_', e.g. --max-delay-samples) and the
  // whole numbers it may be set to.
  static const std::vector<FieldRow<Limits>>& fields();
  bool operator==(const Limits&) const = default;
};

// Sets the cap named `key` to `value`. Returns "" when done, else what is
// wrong (no such cap, or not a whole number in its range), naming the range.
std::string set_limit(Limits& limits, const std::string& key, double value);

}  // namespace mpm::config
