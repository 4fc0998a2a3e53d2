#include "daemon/data_input.hpp"

#include <cstdio>
#include <fstream>

#include "config/csv_stream.hpp"
#ifdef MPM_HAVE_LCM_LOG
#include "daemon/lcm_log_reader.hpp"
#endif

namespace mpm {
namespace {

#ifdef MPM_HAVE_LCM_LOG
bool lcm_log(const std::string& path) { return transport::is_lcm_log(path); }
#else
// A build without LCM: such a file gets a clear error instead of a CSV
// error about binary bytes (the same test as transport::is_lcm_log).
bool lcm_log(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char magic[4] = {};
  if (in.read(magic, 4) && magic[0] == '\xED' && magic[1] == '\xA1' && magic[2] == '\xDA' && magic[3] == '\x01')
    throw config::ConfigError(path + ": an LCM log, and this mpm was built without LCM (MPM_BUILD_TRANSPORTS=OFF)");
  return false;
}
#endif

}  // namespace

void report_notes(const config::RowSource& source, const DataOptions& options) {
  const std::string notes = source.notes();
  if (!notes.empty() && !options.report_as.empty())
    std::fprintf(stderr, "%s: %s\n", options.report_as.c_str(), notes.c_str());
}

std::unique_ptr<config::RowSource> open_data(const std::string& path, const PlantModel& plant,
                                             const DataOptions& options) {
#ifdef MPM_HAVE_LCM_LOG
  if (lcm_log(path)) {
    transport::LcmLogSettings settings;
    settings.channel = options.lcm_channel;
    return std::make_unique<transport::LcmLogRowReader>(path, plant, settings);
  }
#else
  (void)plant, (void)options, (void)lcm_log(path);
#endif
  return std::make_unique<config::CsvRowReader>(path, options.limits);
}

config::Recording load_data(const std::string& path, const PlantModel& plant, const DataOptions& options) {
  if (!lcm_log(path)) return config::load_recording(path, options.limits);  // the whole-file reader, size-capped
  const auto source = open_data(path, plant, options);
  config::Recording rec = config::read_rows(*source);
  report_notes(*source, options);
  return rec;
}

}  // namespace mpm
