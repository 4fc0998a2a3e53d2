#include "transport/fake_transport.hpp"

#include <algorithm>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <variant>
#include <vector>

namespace mpm::transport {

namespace {
using Message = std::variant<msg::Sample, msg::Alarm, msg::Status, msg::Diagnosis>;
constexpr int kMaxBatch = 256;
}  // namespace

// One inbox per attached transport; publish() appends to every inbox whose
// owner subscribed to that kind.
class FakeBus {
 public:
  struct Inbox {
    std::deque<Message> messages;
    bool samples = false;
    bool alarms = false;
    bool status = false;
    bool diagnoses = false;
  };

  std::shared_ptr<Inbox> attach() {
    std::lock_guard lock(mutex_);
    inboxes_.push_back(std::make_shared<Inbox>());
    return inboxes_.back();
  }

  void detach(const std::shared_ptr<Inbox>& inbox) {
    std::lock_guard lock(mutex_);
    inboxes_.erase(std::remove(inboxes_.begin(), inboxes_.end(), inbox), inboxes_.end());
  }

  template <typename Fn>
  void with_lock(Fn&& fn) {
    std::lock_guard lock(mutex_);
    fn();
  }

  void deliver(const Message& message) {
    {
      std::lock_guard lock(mutex_);
      for (auto& inbox : inboxes_) {
        if (wants(*inbox, message)) inbox->messages.push_back(message);
      }
    }
    arrived_.notify_all();
  }

  // Moves up to kMaxBatch messages of `inbox` into `out`, waiting up to
  // `timeout` for the first one.
  void take(Inbox& inbox, std::chrono::milliseconds timeout, std::vector<Message>& out) {
    std::unique_lock lock(mutex_);
    arrived_.wait_for(lock, timeout, [&] { return !inbox.messages.empty(); });
    while (!inbox.messages.empty() && static_cast<int>(out.size()) < kMaxBatch) {
      out.push_back(std::move(inbox.messages.front()));
      inbox.messages.pop_front();
    }
  }

 private:
  static bool wants(const Inbox& inbox, const Message& message) {
    if (std::holds_alternative<msg::Sample>(message)) return inbox.samples;
    if (std::holds_alternative<msg::Alarm>(message)) return inbox.alarms;
    if (std::holds_alternative<msg::Diagnosis>(message)) return inbox.diagnoses;
    return inbox.status;
  }

  std::mutex mutex_;
  std::condition_variable arrived_;
  std::vector<std::shared_ptr<Inbox>> inboxes_;
};

namespace {

class FakeTransport final : public Transport {
 public:
  explicit FakeTransport(std::shared_ptr<FakeBus> bus) : bus_(std::move(bus)), inbox_(bus_->attach()) {}
  ~FakeTransport() override { bus_->detach(inbox_); }

  bool subscribe_samples(SampleHandler handler) override {
    return subscribe(on_sample_, std::move(handler), &FakeBus::Inbox::samples);
  }
  bool subscribe_alarms(AlarmHandler handler) override {
    return subscribe(on_alarm_, std::move(handler), &FakeBus::Inbox::alarms);
  }
  bool subscribe_status(StatusHandler handler) override {
    return subscribe(on_status_, std::move(handler), &FakeBus::Inbox::status);
  }
  bool subscribe_diagnoses(DiagnosisHandler handler) override {
    return subscribe(on_diagnosis_, std::move(handler), &FakeBus::Inbox::diagnoses);
  }

  bool publish(const msg::Sample& sample) override { return deliver(sample); }
  bool publish(const msg::Alarm& alarm) override { return deliver(alarm); }
  bool publish(const msg::Status& status) override { return deliver(status); }
  bool publish(const msg::Diagnosis& diagnosis) override { return deliver(diagnosis); }

  int handle(std::chrono::milliseconds timeout) override {
    batch_.clear();
    bus_->take(*inbox_, timeout, batch_);
    for (const auto& message : batch_) dispatch(message);
    return static_cast<int>(batch_.size());
  }

  int fd() const override { return -1; }
  std::uint64_t receive_errors() const override { return 0; }
  std::string describe() const override { return "fake in-process bus"; }

 private:
  // From now on the bus queues this kind for us (the inbox flag `wanted`).
  template <typename Handler>
  bool subscribe(Handler& slot, Handler handler, bool FakeBus::Inbox::*wanted) {
    slot = std::move(handler);
    bus_->with_lock([&] { (*inbox_).*wanted = true; });
    return true;
  }

  template <typename M>
  bool deliver(const M& message) {
    bus_->deliver(Message{message});
    return true;
  }

  void dispatch(const Message& message) {
    if (const auto* s = std::get_if<msg::Sample>(&message)) {
      if (on_sample_) on_sample_(*s);
    } else if (const auto* a = std::get_if<msg::Alarm>(&message)) {
      if (on_alarm_) on_alarm_(*a);
    } else if (const auto* st = std::get_if<msg::Status>(&message)) {
      if (on_status_) on_status_(*st);
    } else if (const auto* d = std::get_if<msg::Diagnosis>(&message)) {
      if (on_diagnosis_) on_diagnosis_(*d);
    }
  }

  std::shared_ptr<FakeBus> bus_;
  std::shared_ptr<FakeBus::Inbox> inbox_;
  std::vector<Message> batch_;
  SampleHandler on_sample_;
  AlarmHandler on_alarm_;
  StatusHandler on_status_;
  DiagnosisHandler on_diagnosis_;
};

}  // namespace

std::shared_ptr<FakeBus> make_fake_bus() { return std::make_shared<FakeBus>(); }

std::unique_ptr<Transport> make_fake_transport(std::shared_ptr<FakeBus> bus) {
  return std::make_unique<FakeTransport>(std::move(bus));
}

}  // namespace mpm::transport
