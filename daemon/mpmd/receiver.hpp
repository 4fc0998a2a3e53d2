// The receiver thread: runs the transport's handle() loop and copies each
// sample into the bounded queue. A full queue drops the sample and counts
// it (the monitor thread reports the count, throttled). The receiver never
// blocks on the monitor, so a slow monitor cannot back the transport up.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <string>
#include <thread>

#include "daemon/mpmd/sample_queue.hpp"
#include "transport/transport.hpp"

namespace mpm {

class Receiver {
 public:
  Receiver(transport::Transport& transport, SampleQueue& queue);
  ~Receiver();
  Receiver(const Receiver&) = delete;
  Receiver& operator=(const Receiver&) = delete;

  // Subscribes to samples and starts the thread. False with `error` set when
  // the subscription fails.
  bool start(std::string& error);
  void stop();  // joins; idempotent

  // Readable (eventfd) when the queue went from empty to non-empty.
  int wake_fd() const noexcept { return wake_fd_; }
  // Consumer side: clears the wake-up before draining the queue.
  void clear_wake() noexcept;

  std::uint64_t dropped() const noexcept { return dropped_.load(std::memory_order_relaxed); }
  bool failed() const noexcept { return failed_.load(std::memory_order_relaxed); }
  // When the thread last came back from handle(): a watchdog ping is honest
  // only while this is recent.
  std::chrono::steady_clock::time_point last_alive() const noexcept;

 private:
  void run();
  void on_sample(const msg::Sample& sample);

  transport::Transport& transport_;
  SampleQueue& queue_;
  int wake_fd_ = -1;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::atomic<bool> failed_{false};
  std::atomic<std::uint64_t> dropped_{0};
  std::atomic<std::int64_t> alive_ns_{0};
};

}  // namespace mpm
