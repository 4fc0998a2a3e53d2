#include "daemon/mpmd/setup.hpp"

#include <fstream>
#include <sstream>
#include <stdexcept>

#include "config/plant_loader.hpp"
#include "core/mimo_model.hpp"
#include "daemon/mpmd/log.hpp"

namespace mpm {
namespace {

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string fingerprint(const config::DaemonConfig& c) {
  const MonitorSettings& m = c.monitor;
  std::ostringstream f;
  f.precision(17);
  f << c.controller_id << '\n'
    << m.ar_order << ' ' << m.input_order << ' ' << m.forgetting << ' ' << m.false_alarm << ' '
    << m.detector.false_alarms_per_year << ' ' << m.detector.sample_time << ' ' << m.detector.crossing_constant << ' '
    << m.outlier_limit << ' ' << m.warmup << ' ' << m.gamma_lambda << ' '
    << m.input_pole << ' ' << c.input_pole_auto << ' ' << c.plain_lags << ' ' << c.settle_samples << ' '
    << c.log_interval << ' ' << c.max_sequence_jump << ' ' << c.stale_after << '\n'
    << c.plant_path << '\n'
    << read_text(c.plant_path);
  return f.str();
}

}  // namespace

std::optional<LoadedConfig> load_config(const std::string& path, std::string& error) {
  try {
    LoadedConfig loaded;
    loaded.config = config::load_daemon_config(path);
    loaded.plant = config::load_plant(loaded.config.plant_path);
    loaded.monitor_fingerprint = fingerprint(loaded.config);
    return loaded;
  } catch (const config::ConfigError& e) {
    error = e.what();
  } catch (const std::exception& e) {
    error = path + ": " + e.what();
  }
  return std::nullopt;
}

std::unique_ptr<MonitorService> make_service(const LoadedConfig& loaded, MonitorService::AlarmSink on_alarm,
                                             std::string& error) {
  ServiceSettings settings;
  settings.controller_id = loaded.config.controller_id;
  settings.monitor = loaded.config.monitor;
  if (loaded.config.input_pole_auto) settings.monitor.input_pole = dominant_pole(loaded.plant);
  settings.plain_lags = loaded.config.plain_lags;
  settings.settle_samples = loaded.config.settle_samples;
  settings.log_interval = loaded.config.log_interval;
  settings.max_sequence_jump = loaded.config.max_sequence_jump;
  settings.stale_after = loaded.config.stale_after;
  try {
    return std::make_unique<MonitorService>(loaded.plant, settings, std::move(on_alarm));
  } catch (const std::exception& e) {
    error = loaded.config.source + ": monitor: " + e.what();
    return nullptr;
  }
}

MonitorService::AlarmSink publish_to(const std::unique_ptr<transport::Transport>& transport) {
  return [&transport](const msg::Alarm& alarm) {
    if (transport && transport->publish(alarm)) return;
    log::write(log::Level::kError, "could not publish the alarm of %s -> %s", alarm.input.c_str(),
               alarm.output.c_str());
  };
}

}  // namespace mpm
