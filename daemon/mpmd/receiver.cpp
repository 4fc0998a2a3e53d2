#include "daemon/mpmd/receiver.hpp"

#include <signal.h>
#include <sys/eventfd.h>
#include <unistd.h>

#include <cstring>

#include "daemon/mpmd/log.hpp"

namespace mpm {
namespace {

// handle() returns at least this often, so stop() is prompt and the
// heartbeat stays fresh without traffic.
constexpr std::chrono::milliseconds kHandleTimeout{100};
// Consecutive transport failures before the receiver gives up (mpmd then
// exits non-zero and systemd restarts it).
constexpr int kMaxFailures = 50;

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

}  // namespace

Receiver::Receiver(transport::Transport& transport, SampleQueue& queue)
    : transport_(transport), queue_(queue), wake_fd_(::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC)) {
  alive_ns_ = now_ns();
}

Receiver::~Receiver() {
  stop();
  if (wake_fd_ >= 0) ::close(wake_fd_);
}

bool Receiver::start(std::string& error) {
  if (wake_fd_ < 0) {
    error = std::string("cannot create an eventfd: ") + std::strerror(errno);
    return false;
  }
  if (!transport_.subscribe_samples([this](const msg::Sample& s) { on_sample(s); })) {
    error = "cannot subscribe to samples on " + transport_.describe();
    return false;
  }
  // Signals are for the main thread: block them here so they interrupt its
  // poll() (and run their flag-setting handlers there).
  sigset_t all, previous;
  sigfillset(&all);
  pthread_sigmask(SIG_BLOCK, &all, &previous);
  thread_ = std::thread([this] { run(); });
  pthread_sigmask(SIG_SETMASK, &previous, nullptr);
  return true;
}

void Receiver::stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

void Receiver::clear_wake() noexcept {
  std::uint64_t value = 0;
  [[maybe_unused]] const ssize_t n = ::read(wake_fd_, &value, sizeof value);
}

std::chrono::steady_clock::time_point Receiver::last_alive() const noexcept {
  return std::chrono::steady_clock::time_point(std::chrono::nanoseconds(alive_ns_.load(std::memory_order_relaxed)));
}

void Receiver::run() {
  int failures = 0;
  while (!stop_.load(std::memory_order_relaxed)) {
    const int rc = transport_.handle(kHandleTimeout);
    alive_ns_.store(now_ns(), std::memory_order_relaxed);
    if (rc >= 0) {
      failures = 0;
      continue;
    }
    if (++failures >= kMaxFailures) {
      log::write(log::Level::kError, "transport %s keeps failing: receiver stopped",
                 transport_.describe().c_str());
      failed_ = true;
      const std::uint64_t one = 1;
      [[maybe_unused]] const ssize_t n = ::write(wake_fd_, &one, sizeof one);
      return;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

void Receiver::on_sample(const msg::Sample& sample) {
  bool was_empty = false;
  if (!queue_.push(sample, was_empty)) {
    dropped_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  if (was_empty) {
    const std::uint64_t one = 1;
    [[maybe_unused]] const ssize_t n = ::write(wake_fd_, &one, sizeof one);
  }
}

}  // namespace mpm
