// The transport seam: a small interface with the shape of LCM's transport
// table (create / subscribe / publish / handle with a timeout / descriptor),
// implemented for LCM, Cyclone DDS and an in-process fake for unit tests.
//
// Threading: handle() and the subscribe calls belong to one thread (the
// receiver); publish() may be called from any thread (both LCM and Cyclone
// allow it, and the fake locks).
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "transport/messages.hpp"
#include "settings/transport_settings.hpp"

namespace mpm::transport {

class Transport {
 public:
  using SampleHandler = std::function<void(const msg::Sample&)>;
  using AlarmHandler = std::function<void(const msg::Alarm&)>;
  using StatusHandler = std::function<void(const msg::Status&)>;

  virtual ~Transport() = default;

  // One handler per kind; call before handle(). A handler runs on the thread
  // that calls handle(); the message it gets is valid during the call only.
  // Return false (and leave the transport unchanged) if the subscription
  // cannot be made.
  virtual bool subscribe_samples(SampleHandler handler) = 0;
  virtual bool subscribe_alarms(AlarmHandler handler) = 0;
  virtual bool subscribe_status(StatusHandler handler) = 0;

  // False when the message could not be sent (too large, transport down).
  virtual bool publish(const msg::Sample& sample) = 0;
  virtual bool publish(const msg::Alarm& alarm) = 0;
  virtual bool publish(const msg::Status& status) = 0;
  // Diagnoses (added later than the three above; a transport without them
  // refuses).
  using DiagnosisHandler = std::function<void(const msg::Diagnosis&)>;
  virtual bool subscribe_diagnoses(DiagnosisHandler handler) {
    (void)handler;
    return false;
  }
  virtual bool publish(const msg::Diagnosis& diagnosis) {
    (void)diagnosis;
    return false;
  }

  // Waits up to `timeout` for messages and dispatches what arrived (a bounded
  // batch) to the handlers. Returns the number dispatched, 0 on timeout, -1
  // when the transport failed.
  virtual int handle(std::chrono::milliseconds timeout) = 0;

  // A descriptor that becomes readable when handle() has work, or -1.
  virtual int fd() const = 0;

  // Messages received that could not be decoded (bad bytes, wrong type hash).
  virtual std::uint64_t receive_errors() const = 0;

  // Creates the publisher of one kind ahead of the first publish(), so that
  // discovery (DDS) is under way by then. A no-op where there is none.
  enum class Topic { kSample, kAlarm, kStatus, kDiagnosis };
  virtual bool advertise(Topic topic) {
    (void)topic;
    return true;
  }

  // Waits until at least `count` sample subscribers are matched. DDS discards
  // what a volatile writer sends before a reader matched; LCM and the fake
  // have no such notion and return true at once.
  virtual bool wait_for_sample_readers(int count, std::chrono::milliseconds timeout) {
    (void)count;
    (void)timeout;
    return true;
  }

  // Waits until what was published has been acknowledged by the matched
  // readers (DDS reliable delivery), up to `timeout`; call before destroying
  // a publisher that just sent its last messages. LCM sends synchronously.
  virtual bool flush(std::chrono::milliseconds timeout) {
    (void)timeout;
    return true;
  }

  // "lcm udpm://..." or "dds domain 0", for logs.
  virtual std::string describe() const = 0;

  // What a received sample may contain (settings/transport_settings.hpp): a sample
  // beyond these is counted in receive_errors() and never handed on. May be
  // called from any thread (a reload with a new plant); a sample being
  // decoded meanwhile is judged by the old or the new limits.
  void set_sample_limits(const SampleLimits& limits) noexcept {
    n_u_.store(limits.n_u, std::memory_order_relaxed);
    n_y_.store(limits.n_y, std::memory_order_relaxed);
    max_channels_.store(limits.max_channels, std::memory_order_relaxed);
    max_extra_.store(limits.max_extra, std::memory_order_relaxed);
    max_string_.store(limits.max_string, std::memory_order_relaxed);
  }
  SampleLimits sample_limits() const noexcept {
    SampleLimits l;
    l.n_u = n_u_.load(std::memory_order_relaxed);
    l.n_y = n_y_.load(std::memory_order_relaxed);
    l.max_channels = max_channels_.load(std::memory_order_relaxed);
    l.max_extra = max_extra_.load(std::memory_order_relaxed);
    l.max_string = max_string_.load(std::memory_order_relaxed);
    return l;
  }

 private:
  std::atomic<std::uint32_t> n_u_{SampleLimits{}.n_u}, n_y_{SampleLimits{}.n_y},
      max_channels_{SampleLimits{}.max_channels}, max_extra_{SampleLimits{}.max_extra},
      max_string_{SampleLimits{}.max_string};
};

// Creates the transport the settings name. Returns nullptr and sets `error`
// to a complete message when it cannot be created (bad URL, no multicast
// route, DDS configuration rejected, built without that transport).
std::unique_ptr<Transport> create(const Settings& settings, std::string& error);

}  // namespace mpm::transport
