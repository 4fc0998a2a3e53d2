// The service configuration, mpmd.yaml: which controller to watch, its plant
// file, the monitor's settings and the transport. Every key but
// controller_id and plant is optional. Errors name the file, line, key and
// what was expected (ConfigError), like the plant loader's.
//
// The keys are the rows of the settings tables (core/field_table.hpp):
// ServiceSettings::monitor_fields() under `monitor:`, ServiceSettings::fields()
// and DaemonConfig::fields() at the top level, Limits::fields() under
// `limits:`; the transport section (settings/transport_settings.hpp) is read
// by hand. deploy/mpmd.yaml lists every key with its default (a test checks
// it), README "Settings" says what each does.
#pragma once

#include <cstdint>
#include <string>

#include "config/limits.hpp"
#include "config/service_settings.hpp"
#include "settings/transport_settings.hpp"

namespace mpm::config {

// The service's settings (ServiceSettings: what the monitoring service
// gets) plus the file's own: where it was read from, the plant, the
// transport, the loop and the checkpoint, the loaders' caps.
struct DaemonConfig : ServiceSettings {
  std::string source;          // the file it was read from
  std::string plant_path;      // resolved against the config file's folder
  transport::Settings transport;
  double status_period = 1.0;  // seconds between status messages
  int queue_capacity = 4096;   // samples buffered between receiver and monitor
  std::string checkpoint_path; // monitor state saved here and resumed at start; "" = none
  double checkpoint_interval = 60.0;  // seconds between checkpoints (and one at SIGTERM)
  Limits limits;               // caps on the plant file (the config file itself: the defaults)

  // The file's top-level keys of its own (ServiceSettings::fields() are the
  // others; controller_id, plant, transport and limits are read apart).
  static const std::vector<FieldRow<DaemonConfig>>& fields();
};

// `base_dir` resolves relative paths (plant, DDS config); "" = as given.
DaemonConfig parse_daemon_config(const std::string& yaml_text, const std::string& source_name,
                                 const std::string& base_dir);
// Also refuses a config or plant file that group or others may write, or that
// another non-root user owns (strict_modes.hpp).
DaemonConfig load_daemon_config(const std::string& path);

}  // namespace mpm::config
