// Bounded hand-off between the receiver thread and the monitor: a
// single-producer single-consumer ring of pre-made sample slots. The producer
// copies into a free slot (assigning into vectors that already have the
// capacity: no allocation once the first samples have sized them); a full
// ring refuses the sample and the caller counts it as dropped.
#pragma once

#include <atomic>
#include <cstddef>
#include <vector>

#include "transport/messages.hpp"

namespace mpm {

class SampleQueue {
 public:
  // Allocates `capacity` slots (at least 2).
  explicit SampleQueue(std::size_t capacity) : slots_(capacity < 2 ? 2 : capacity) {}

  // Producer. False when full (the sample is not queued). Sets `was_empty`
  // when the consumer may be waiting for it.
  bool push(const msg::Sample& sample, bool& was_empty) {
    const std::size_t head = head_.load(std::memory_order_relaxed);
    const std::size_t tail = tail_.load(std::memory_order_acquire);
    if (head - tail >= slots_.size()) return false;
    slots_[head % slots_.size()] = sample;
    was_empty = head == tail;
    head_.store(head + 1, std::memory_order_release);
    return true;
  }

  // Consumer: the oldest sample or nullptr; valid until pop().
  const msg::Sample* front() const noexcept {
    const std::size_t tail = tail_.load(std::memory_order_relaxed);
    if (tail == head_.load(std::memory_order_acquire)) return nullptr;
    return &slots_[tail % slots_.size()];
  }
  void pop() noexcept { tail_.store(tail_.load(std::memory_order_relaxed) + 1, std::memory_order_release); }

  std::size_t size() const noexcept {
    return head_.load(std::memory_order_acquire) - tail_.load(std::memory_order_acquire);
  }
  std::size_t capacity() const noexcept { return slots_.size(); }

 private:
  std::vector<msg::Sample> slots_;
  alignas(64) std::atomic<std::size_t> head_{0};  // next slot to fill (producer)
  alignas(64) std::atomic<std::size_t> tail_{0};  // next slot to read (consumer)
};

}  // namespace mpm
