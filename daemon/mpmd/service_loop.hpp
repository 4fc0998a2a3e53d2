// mpmd's main loop, on the main thread: drains the receive queue into the
// monitor, publishes status periodically, feeds the systemd watchdog while
// the receiver is alive, and applies SIGHUP reloads (a configuration that
// fails to load is logged and the running one kept). The flags it watches
// are set by signal handlers (or tests); nothing else happens in a handler.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>

#include "daemon/mpmd/monitor_service.hpp"
#include "daemon/mpmd/notifier.hpp"
#include "daemon/mpmd/receiver.hpp"
#include "daemon/mpmd/sample_queue.hpp"
#include "daemon/mpmd/setup.hpp"
#include "daemon/mpmd/throttle.hpp"
#include "transport/transport.hpp"

namespace mpm {

class ServiceLoop {
 public:
  using Clock = std::chrono::steady_clock;

  ServiceLoop(std::string config_path, LoadedConfig running, std::unique_ptr<MonitorService> service,
              SampleQueue& queue, Receiver& receiver, transport::Transport& transport, Notifier& notifier);

  // Until `stop` is set. Returns the process exit code: 0 after a stop, 1
  // when the transport failed for good.
  int run(const std::atomic<bool>& stop, std::atomic<bool>& reload);

  const MonitorService& service() const noexcept { return *service_; }

 private:
  void drain(Clock::time_point now);
  void account_losses(Clock::time_point now);
  void publish_status(Clock::time_point now);
  void feed_watchdog(Clock::time_point now);
  void apply_reload();
  void reload_failed(const std::string& error, bool report, const char* suppressed);
  void write_checkpoint(Clock::time_point now, bool final_one);
  void wait(Clock::time_point until);

  std::string config_path_;
  LoadedConfig running_;
  std::unique_ptr<MonitorService> service_;
  SampleQueue& queue_;
  Receiver& receiver_;
  transport::Transport& transport_;
  Notifier& notifier_;

  Clock::time_point started_;
  Clock::time_point next_status_;
  Clock::time_point next_watchdog_;
  std::uint64_t dropped_seen_ = 0;
  std::uint64_t receive_errors_seen_ = 0;
  std::uint64_t status_failures_ = 0;
  Clock::time_point next_checkpoint_;
  Throttle checkpoint_failures_;
  msg::Status status_;
  Throttle reload_throttle_;
  std::string last_reload_error_;  // the last reload error logged ("" after a good reload)
};

}  // namespace mpm
