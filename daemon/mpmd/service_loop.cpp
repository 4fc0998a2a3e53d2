#include "daemon/mpmd/service_loop.hpp"

#include <poll.h>

#include <algorithm>
#include <cinttypes>
#include <cstdio>

#include "daemon/mpmd/checkpoint.hpp"
#include "daemon/mpmd/log.hpp"

namespace mpm {
namespace {

// Samples handled between two looks at the clock: bounds how late a status
// or a watchdog ping can be while samples pour in.
constexpr int kDrainBatch = 4096;
// Longest sleep: flags set by a signal that arrived between two polls are
// seen at least this often.
constexpr std::chrono::milliseconds kMaxWait{200};

std::int64_t unix_micros() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

std::chrono::steady_clock::duration period(double seconds) {
  return std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(seconds));
}

}  // namespace

ServiceLoop::ServiceLoop(std::string config_path, LoadedConfig running, std::unique_ptr<MonitorService> service,
                         SampleQueue& queue, Receiver& receiver, transport::Transport& transport,
                         Notifier& notifier)
    : config_path_(std::move(config_path)),
      running_(std::move(running)),
      service_(std::move(service)),
      queue_(queue),
      receiver_(receiver),
      transport_(transport),
      notifier_(notifier) {}

int ServiceLoop::run(const std::atomic<bool>& stop, std::atomic<bool>& reload) {
  started_ = Clock::now();
  next_status_ = started_;  // a first status at once: listeners see the monitor is up
  next_watchdog_ = started_;
  next_checkpoint_ = started_ + period(running_.config.checkpoint_interval);
  checkpoint_failures_.set_interval(std::chrono::duration<double>(running_.config.log_interval));
  while (!stop.load()) {
    if (reload.exchange(false)) apply_reload();
    if (receiver_.failed()) {
      log::write(log::Level::kError, "the transport failed: exiting");
      return 1;
    }
    drain(Clock::now());
    service_->poll_diagnoses([this](const msg::Diagnosis& d) {
      if (!transport_.publish(d)) log::write(log::Level::kError, "could not publish the diagnosis of %s", d.output.c_str());
    });
    const auto now = Clock::now();
    account_losses(now);
    service_->check_health(now);
    if (now >= next_status_) publish_status(now);
    feed_watchdog(now);
    if (now >= next_checkpoint_) write_checkpoint(now, false);
    if (queue_.size() > 0) continue;  // more than a batch waiting
    auto until = std::min(next_status_, now + kMaxWait);
    if (notifier_.watchdog_period()) until = std::min(until, next_watchdog_);
    if (!running_.config.checkpoint_path.empty()) until = std::min(until, next_checkpoint_);
    wait(until);
  }
  drain(Clock::now());  // what arrived before the stop, then the final counts and state
  publish_status(Clock::now());
  write_checkpoint(Clock::now(), true);
  return 0;
}

void ServiceLoop::drain(Clock::time_point now) {
  receiver_.clear_wake();
  for (int n = 0; n < kDrainBatch; ++n) {
    const msg::Sample* sample = queue_.front();
    if (sample == nullptr) return;
    service_->on_sample(*sample, now);
    queue_.pop();
  }
}

void ServiceLoop::account_losses(Clock::time_point now) {
  const std::uint64_t dropped = receiver_.dropped();
  service_->add_dropped(dropped - dropped_seen_, now);
  dropped_seen_ = dropped;
  const std::uint64_t errors = transport_.receive_errors();
  service_->add_receive_errors(errors - receive_errors_seen_, now);
  receive_errors_seen_ = errors;
}

void ServiceLoop::publish_status(Clock::time_point now) {
  const auto uptime = std::chrono::duration_cast<std::chrono::milliseconds>(now - started_).count();
  service_->fill_status(status_, unix_micros(), uptime);
  if (!transport_.publish(status_) && status_failures_++ == 0) {
    log::write(log::Level::kError, "could not publish the status on %s", transport_.describe().c_str());
  }
  next_status_ = now + period(running_.config.status_period);
}

// Ping only while the receiver thread keeps coming back from the transport:
// a wedged receiver then lets systemd's watchdog restart the service.
void ServiceLoop::feed_watchdog(Clock::time_point now) {
  const auto wd = notifier_.watchdog_period();
  if (!wd || now < next_watchdog_) return;
  if (now - receiver_.last_alive() < *wd) notifier_.watchdog();
  next_watchdog_ = now + *wd;
}

// The running configuration stays. A different error is news to the operator
// who just edited the file: reported whatever the throttle says (a storm
// repeats one error).
void ServiceLoop::reload_failed(const std::string& error, bool report, const char* suppressed) {
  if (report || error != last_reload_error_) {
    log::write(log::Level::kError, "reload failed, keeping the running configuration: %s%s", error.c_str(),
               suppressed);
    last_reload_error_ = error;
  }
  notifier_.ready("reload failed; running the previous configuration");
}

// A SIGHUP storm must not flood the journal: the lines of a reload are
// rate-limited like every other kind of log line (the first at once, then
// at most one per log_interval, saying how many reloads were not reported);
// a reload error other than the last one logged, new monitor settings and
// the first good reload after errors are always reported.
void ServiceLoop::apply_reload() {
  notifier_.reloading();
  reload_throttle_.set_interval(std::chrono::duration<double>(running_.config.log_interval));
  const bool report = reload_throttle_.event(Clock::now());
  char suppressed[64] = "";
  if (report && reload_throttle_.suppressed() > 0) {
    std::snprintf(suppressed, sizeof suppressed, " (%" PRIu64 " more reloads since the last report)",
                  reload_throttle_.suppressed());
  }
  std::string error;
  auto next = load_config(config_path_, error);
  if (!next) {
    reload_failed(error, report, suppressed);
    return;
  }
  const auto& was = running_.config.transport;
  const auto& now = next->config.transport;
  if (was != now || running_.config.queue_capacity != next->config.queue_capacity) {
    if (report) {
      log::write(log::Level::kWarning, "transport and queue settings take effect at the next restart%s", suppressed);
    }
  }
  if (!next->same_monitor(running_)) {
    auto service = make_service(*next, service_->alarm_sink(), error);
    if (!service) {
      reload_failed(error, report, suppressed);
      return;
    }
    service_->retire("reloaded with new settings");
    service_ = std::move(service);
    transport::SampleLimits limits = transport_.sample_limits();
    limits.n_u = static_cast<std::uint32_t>(next->plant.n_inputs());
    limits.n_y = static_cast<std::uint32_t>(next->plant.n_outputs());
    transport_.set_sample_limits(limits);
    // Always said: the statistics restart (a storm of SIGHUPs over one file
    // changes the settings once).
    log::write(log::Level::kNotice, "reloaded %s: new monitor settings, statistics start again%s",
               config_path_.c_str(), suppressed);
  } else {
    if (report || !last_reload_error_.empty()) {  // throttled, unless it ends a run of errors
      log::write(log::Level::kNotice, "reloaded %s: monitor unchanged, statistics kept%s", config_path_.c_str(),
                 suppressed);
    }
  }
  last_reload_error_.clear();
  running_ = std::move(*next);
  notifier_.ready("reloaded");
}

// The whole state, written atomically (checkpoint.hpp). On the main thread,
// between samples: the state is consistent and the copy costs about a
// millisecond for a 2x2 plant (the samples meanwhile wait in the queue).
void ServiceLoop::write_checkpoint(Clock::time_point now, bool final_one) {
  next_checkpoint_ = now + period(running_.config.checkpoint_interval);
  const std::string& path = running_.config.checkpoint_path;
  if (path.empty()) return;
  std::string error;
  const auto bytes = checkpoint::encode(*service_, checkpoint_fingerprint(running_));
  if (!checkpoint::write_atomically(path, bytes, error)) {
    if (checkpoint_failures_.event(now)) {
      log::write(log::Level::kError, "checkpoint not written: %s", error.c_str());
    }
    return;
  }
  if (final_one) {
    log::write(log::Level::kNotice, "state saved to %s (%zu bytes, last sample %" PRId64 ")", path.c_str(),
               bytes.size(), service_->last_sequence());
  }
}

void ServiceLoop::wait(Clock::time_point until) {
  const auto now = Clock::now();
  if (until <= now) return;
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(until - now).count() + 1;
  pollfd p{receiver_.wake_fd(), POLLIN, 0};
  ::poll(&p, 1, static_cast<int>(ms));  // EINTR (a signal) just ends the wait early
}

}  // namespace mpm
