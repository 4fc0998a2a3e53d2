// Rate limit for log lines of one kind (LCM's logger reports drops once a
// second; we do the same per event kind): the first event is reported at once,
// later ones at most once per interval, with how many happened in between.
// Allocation free; not thread safe (one owner).
#pragma once

#include <chrono>
#include <cstdint>

namespace mpm {

class Throttle {
 public:
  using Clock = std::chrono::steady_clock;

  explicit Throttle(std::chrono::duration<double> interval = std::chrono::seconds(60)) noexcept
      : interval_(std::chrono::duration_cast<Clock::duration>(interval)) {}

  // Counts one event; true when it should be reported now. `suppressed()`
  // then tells how many were not reported since the last report.
  bool event(Clock::time_point now) noexcept {
    ++pending_;
    if (reported_once_ && now - last_ < interval_) return false;
    reported_once_ = true;
    last_ = now;
    suppressed_ = pending_ - 1;
    pending_ = 0;
    return true;
  }

  std::uint64_t suppressed() const noexcept { return suppressed_; }
  void set_interval(std::chrono::duration<double> interval) noexcept {
    interval_ = std::chrono::duration_cast<Clock::duration>(interval);
  }

 private:
  Clock::duration interval_;
  Clock::time_point last_{};
  bool reported_once_ = false;
  std::uint64_t pending_ = 0;     // events since the last report, this one included
  std::uint64_t suppressed_ = 0;  // events between the last two reports
};

}  // namespace mpm
