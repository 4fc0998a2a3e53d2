#include "daemon/mpmd/notifier.hpp"

#include <systemd/sd-daemon.h>

#include <cstdint>

namespace mpm {

Notifier::Notifier() {
  std::uint64_t usec = 0;
  if (sd_watchdog_enabled(0, &usec) > 0 && usec > 0) {
    watchdog_period_ = std::chrono::microseconds(static_cast<std::int64_t>(usec / 2));
  }
}

void Notifier::ready(const std::string& status) { sd_notify(0, ("READY=1\nSTATUS=" + status).c_str()); }
void Notifier::reloading() { sd_notify(0, "RELOADING=1\nSTATUS=reloading the configuration"); }
void Notifier::stopping() { sd_notify(0, "STOPPING=1\nSTATUS=stopping"); }
void Notifier::status(const std::string& text) { sd_notify(0, ("STATUS=" + text).c_str()); }
void Notifier::watchdog() { sd_notify(0, "WATCHDOG=1"); }

}  // namespace mpm
