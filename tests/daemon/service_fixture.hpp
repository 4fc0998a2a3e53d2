// Shared set-up of the MonitorService tests: the repository's Wood-Berry plant
// file, monitor settings tuned for short test runs, and a recorder of the
// alarms and log lines the service produces.
#pragma once

#include <string>
#include <vector>

#include "config/plant_loader.hpp"
#include "daemon/mpmd/log.hpp"
#include "daemon/mpmd/monitor_service.hpp"
#include "daemon/mpmd/setup.hpp"

namespace mpm::test {

inline PlantModel wood_berry_plant() { return config::load_plant(MPM_SOURCE_DIR "/config/wood-berry.yaml"); }

// Shorter memory and a stricter level than the defaults: a test run of a few
// thousand samples must raise and clear, and never raise by chance.
inline MonitorSettings fast_settings() {
  MonitorSettings s;
  s.ar_order = 5;
  s.input_order = 10;  // covers G21's 8-sample delay
  s.forgetting = 0.995;
  s.false_alarm = 1e-5;
  return s;
}

inline ServiceSettings fast_service(const std::string& controller = "wb") {
  ServiceSettings s;
  s.controller_id = controller;
  s.monitor = fast_settings();
  s.settle_samples = 100;
  s.log_interval = 3600;  // "logged once" within a test
  s.diagnosis_window = 0;  // no diagnosis thread unless a test asks for one
  return s;
}

// What mpmd would load for controller "wb" on the Wood-Berry plant, with the
// fast settings and a status every `status_period` seconds.
inline LoadedConfig wood_berry_config(double status_period) {
  LoadedConfig loaded;
  loaded.config.controller_id = "wb";
  loaded.config.status_period = status_period;
  loaded.config.monitor = fast_settings();
  loaded.config.settle_samples = 100;
  loaded.config.log_interval = 3600;  // "logged once" within a test
  loaded.plant = wood_berry_plant();
  return loaded;
}

// Collects log lines while alive (the service logs through mpm::log).
class LogCapture {
 public:
  LogCapture() {
    log::set_sink([this](log::Level, std::string_view line) { lines.emplace_back(line); });
  }
  ~LogCapture() { log::set_sink({}); }
  LogCapture(const LogCapture&) = delete;
  LogCapture& operator=(const LogCapture&) = delete;

  int count(const std::string& needle) const {
    int n = 0;
    for (const auto& l : lines) n += l.find(needle) != std::string::npos ? 1 : 0;
    return n;
  }
  std::vector<std::string> lines;
};

}  // namespace mpm::test
