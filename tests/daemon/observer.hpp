// The operator's side in a test: a transport that records every alarm and
// the latest status per controller, handled on its own thread, with waits
// that poll conditions (never fixed sleeps).
#pragma once

#include <atomic>
#include <condition_variable>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "transport/transport.hpp"

namespace mpm::test {

class Observer {
 public:
  explicit Observer(transport::Transport& t) : transport_(t) {
    t.subscribe_alarms([this](const msg::Alarm& a) {
      std::lock_guard lock(mutex_);
      alarms_.push_back(a);
      changed_.notify_all();
    });
    t.subscribe_status([this](const msg::Status& s) {
      std::lock_guard lock(mutex_);
      status_[s.controller_id] = s;
      ++status_count_[s.controller_id];
      changed_.notify_all();
    });
    t.subscribe_diagnoses([this](const msg::Diagnosis& d) {
      std::lock_guard lock(mutex_);
      diagnoses_.push_back(d);
      changed_.notify_all();
    });
    thread_ = std::thread([this] {
      while (!stop_) transport_.handle(std::chrono::milliseconds(50));
    });
  }
  ~Observer() {
    stop_ = true;
    thread_.join();
  }
  Observer(const Observer&) = delete;
  Observer& operator=(const Observer&) = delete;

  std::optional<msg::Status> status(const std::string& controller) const {
    std::lock_guard lock(mutex_);
    auto it = status_.find(controller);
    if (it == status_.end()) return std::nullopt;
    return it->second;
  }
  int status_count(const std::string& controller) const {
    std::lock_guard lock(mutex_);
    auto it = status_count_.find(controller);
    return it == status_count_.end() ? 0 : it->second;
  }
  std::vector<msg::Alarm> alarms() const {
    std::lock_guard lock(mutex_);
    return alarms_;
  }
  std::vector<msg::Diagnosis> diagnoses() const {
    std::lock_guard lock(mutex_);
    return diagnoses_;
  }

  // Waits until `pred(status)` holds for the controller's latest status.
  template <typename Pred>
  bool wait_status(const std::string& controller, Pred&& pred,
                   std::chrono::milliseconds timeout = std::chrono::seconds(30)) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, timeout, [&] {
      auto it = status_.find(controller);
      return it != status_.end() && pred(it->second);
    });
  }
  // Waits until `pred(alarms)` holds for all alarms received so far.
  template <typename Pred>
  bool wait_alarms(Pred&& pred, std::chrono::milliseconds timeout = std::chrono::seconds(30)) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, timeout, [&] { return pred(alarms_); });
  }

 private:
  transport::Transport& transport_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<msg::Alarm> alarms_;
  std::vector<msg::Diagnosis> diagnoses_;
  std::map<std::string, msg::Status> status_;
  std::map<std::string, int> status_count_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

}  // namespace mpm::test
