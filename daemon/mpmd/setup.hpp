// The set-up steps of mpmd, each a small function so that main() reads as
// the sequence it is: configuration -> monitor -> transport -> ready.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "config/daemon_config.hpp"
#include "core/plant_model.hpp"
#include "daemon/mpmd/monitor_service.hpp"
#include "transport/transport.hpp"

namespace mpm {

struct LoadedConfig {
  config::DaemonConfig config;
  PlantModel plant;
  // The plant file's text: with the service settings (config's
  // ServiceSettings part), what the monitor depends on. A reload that
  // leaves both unchanged keeps the running statistics.
  std::string plant_text;

  // Same service settings and plant: the running monitor stays.
  bool same_monitor(const LoadedConfig& other) const {
    return static_cast<const config::ServiceSettings&>(config) == other.config && config.plant_path == other.config.plant_path &&
           plant_text == other.plant_text;
  }
};

// Reads mpmd.yaml and its plant file. On failure returns nothing and sets
// `error` to one complete message (file, line, key, what was expected).
std::optional<LoadedConfig> load_config(const std::string& path, std::string& error);

// The monitoring service for a loaded configuration; nullptr and `error`
// when the settings do not fit the plant.
std::unique_ptr<MonitorService> make_service(const LoadedConfig& loaded, MonitorService::AlarmSink on_alarm,
                                             std::string& error);

// Loads the configured checkpoint (checkpoint.hpp) into `*service` when it
// was written for this plant and these settings, else leaves the service
// fresh (rebuilt when a refused file had partly overwritten it); logs which
// and why. True when it resumed. False with `error` set only when the
// service could not be rebuilt.
bool resume_from_checkpoint(std::unique_ptr<MonitorService>& service, const LoadedConfig& loaded,
                            std::string& error);
// The checkpoint's fingerprint of a configuration: a hash of every service
// setting (from the settings tables), the controller, the plant's path and text.
std::uint64_t checkpoint_fingerprint(const LoadedConfig& loaded);

// An alarm sink that publishes through `*transport` (once it is set) and
// logs a failure to publish.
MonitorService::AlarmSink publish_to(const std::unique_ptr<transport::Transport>& transport);

}  // namespace mpm
