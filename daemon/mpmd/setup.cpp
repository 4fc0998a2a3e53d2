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

}  // namespace

std::optional<LoadedConfig> load_config(const std::string& path, std::string& error) {
  try {
    LoadedConfig loaded;
    loaded.config = config::load_daemon_config(path);
    loaded.plant = config::load_plant(loaded.config.plant_path, loaded.config.limits);
    loaded.plant_text = read_text(loaded.config.plant_path);
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
  ServiceSettings settings = loaded.config;  // the service's part of the file
  if (settings.input_pole_auto) settings.monitor.input_pole = dominant_pole(loaded.plant);
  try {
    return std::make_unique<MonitorService>(loaded.plant, settings, std::move(on_alarm));
  } catch (const std::exception& e) {
    error = loaded.config.source + ": monitor: " + e.what();
    return nullptr;
  }
}

std::uint64_t checkpoint_fingerprint(const LoadedConfig& loaded) {
  const config::ServiceSettings& s = loaded.config;
  std::string f = s.controller_id + '\n' + (s.input_pole_auto ? "input_pole=auto\n" : "");
  config::append_values(config::ServiceSettings::monitor_fields(), s, f);
  config::append_values(config::ServiceSettings::fields(), s, f);
  f += '\n' + loaded.config.plant_path + '\n' + loaded.plant_text;
  return checkpoint::fnv1a(f.data(), f.size());
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
