// A recording read one row at a time, whatever file it came from: the CSV
// reader (csv_stream.hpp) and the LCM log reader (daemon/lcm_log_reader.hpp)
// both hand out rows of doubles under column names, so the streaming monitor
// (daemon/stream_monitor.hpp) reads either with the same code.
#pragma once

#include <string>
#include <vector>

#include "config/plant_loader.hpp"

namespace mpm::config {

class RowSource {
 public:
  virtual ~RowSource() = default;
  virtual const std::vector<std::string>& names() const = 0;
  // The file, for messages.
  virtual const std::string& source() const = 0;
  // The next row's values (one per column, NaN = missing) into `row`; false
  // at the end. Throws ConfigError naming the file and where in it.
  virtual bool next(std::vector<double>& row) = 0;
  // What the reader skipped or counted, one line for a person; empty when
  // there is nothing to say (a CSV read in full).
  virtual std::string notes() const { return {}; }
};

// Every row of `source` as a Recording (source, names, samples x columns).
Recording read_rows(RowSource& source);

}  // namespace mpm::config
