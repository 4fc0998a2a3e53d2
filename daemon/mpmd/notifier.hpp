// Talks to systemd through sd_notify (libsystemd): READY=1 once serving,
// WATCHDOG=1 while healthy, RELOADING=1 / READY=1 around a reload,
// STOPPING=1 on the way out, STATUS= lines for `systemctl status`. Without
// NOTIFY_SOCKET (not started by systemd) every call is a harmless no-op.
#pragma once

#include <chrono>
#include <optional>
#include <string>

namespace mpm {

class Notifier {
 public:
  Notifier();

  void ready(const std::string& status);
  void reloading();
  void stopping();
  void status(const std::string& text);
  void watchdog();

  // How often to ping: half of WatchdogSec, or nothing when no watchdog.
  std::optional<std::chrono::microseconds> watchdog_period() const noexcept { return watchdog_period_; }

 private:
  std::optional<std::chrono::microseconds> watchdog_period_;
};

}  // namespace mpm
