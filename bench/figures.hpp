// The figures of `mpm bench` (issue 4): one named number with a unit, or no
// number and a note saying why it is unavailable.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace mpm::bench {

struct Figure {
  std::string name;
  std::optional<double> value;  // nullopt: unavailable, see note
  std::string unit;
  std::string note;             // how it was measured, or why it is missing
};

struct BenchOptions {
  bool quick = false;  // shorten every measurement (smoke test): numbers are rough
  // Progress lines ("measuring ..."), e.g. to stderr; may be empty.
  std::function<void(const std::string&)> progress;
};

// Runs every measurement in turn, in this process (the memory figures in a
// forked child). Never throws for an unavailable figure: it gets a note.
std::vector<Figure> run_all(const BenchOptions& options);

// "<cpu model name>, <n> logical CPUs" from /proc/cpuinfo.
std::string machine_description();

// {"machine": "...", "figures": [{"name": ..., "value": ..., "unit": ..., "note": ...}]}
std::string to_json(const std::string& machine, const std::vector<Figure>& figures);
// A fixed-width table, one figure per line.
std::string to_table(const std::string& machine, const std::vector<Figure>& figures);

}  // namespace mpm::bench
