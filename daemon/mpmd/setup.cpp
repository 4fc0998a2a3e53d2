#include "daemon/mpmd/setup.hpp"

#include <fstream>
#include <sstream>
#include <stdexcept>

#include "config/plant_loader.hpp"
#include "core/mimo_model.hpp"
#include "daemon/mpmd/checkpoint.hpp"
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
    loaded.plant = config::load_plant(loaded.config.plant_path, loaded.config.limits);
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
  settings.diagnosis_window = loaded.config.diagnosis_window;
  settings.scan_interval = loaded.config.scan_interval;
  try {
    return std::make_unique<MonitorService>(loaded.plant, settings, std::move(on_alarm));
  } catch (const std::exception& e) {
    error = loaded.config.source + ": monitor: " + e.what();
    return nullptr;
  }
}

std::uint64_t checkpoint_fingerprint(const LoadedConfig& loaded) {
  return checkpoint::fnv1a(loaded.monitor_fingerprint.data(), loaded.monitor_fingerprint.size());
}

bool resume_from_checkpoint(std::unique_ptr<MonitorService>& service, const LoadedConfig& loaded,
                            std::string& error) {
  const std::string& path = loaded.config.checkpoint_path;
  if (path.empty()) return false;
  std::string why;
  switch (checkpoint::load(*service, path, checkpoint_fingerprint(loaded), why)) {
    case checkpoint::Outcome::kResumed: {
      const ServiceCounters& c = service->counters();
      log::write(log::Level::kNotice,
                 "resumed from checkpoint %s: %llu samples seen, %llu used, last sample %lld", path.c_str(),
                 static_cast<unsigned long long>(c.seen),
                 static_cast<unsigned long long>(service->monitor().counters().used),
                 static_cast<long long>(service->last_sequence()));
      return true;
    }
    case checkpoint::Outcome::kAbsent:
      log::write(log::Level::kNotice, "%s: starting fresh", why.c_str());
      return false;
    case checkpoint::Outcome::kOtherSetup:
      log::write(log::Level::kNotice, "checkpoint %s: starting fresh (it will be replaced)", why.c_str());
      return false;
    case checkpoint::Outcome::kRefused:
      break;
  }
  log::write(log::Level::kWarning, "checkpoint %s: refused, starting fresh (it will be replaced)", why.c_str());
  service = make_service(loaded, service->alarm_sink(), error);
  if (!service) return false;
  return false;
}

MonitorService::AlarmSink publish_to(const std::unique_ptr<transport::Transport>& transport) {
  return [&transport](const msg::Alarm& alarm) {
    if (transport && transport->publish(alarm)) return;
    log::write(log::Level::kError, "could not publish the alarm of %s -> %s", alarm.input.c_str(),
               alarm.output.c_str());
  };
}

}  // namespace mpm
