// LCM adapter. Each channel carries one type; received bytes are decoded into
// a member message object and converted into a member plain message, both
// reused, so steady-state receiving does not allocate. Publishing encodes
// into a reused buffer under a mutex (publish may come from any thread).
//
// It talks to LCM's C API: the C++ wrapper's member-function subscriptions
// (lcm-cpp-impl.hpp, LCM 1.3.1) hand the callback a wrong object when built
// with -fsanitize=undefined, and the C API is all we need.
#include "transport/lcm_transport.hpp"

#include <poll.h>

#include <cerrno>

#include <atomic>
#include <mutex>
#include <vector>

#include <lcm/lcm.h>

#include "transport/lcm_codec.hpp"
#include "transport/lcm_wire.hpp"

namespace mpm::transport {

namespace {

// LCM's own per-subscription queue (default 30 messages) sits in front of
// ours; a deeper one absorbs bursts while the receiver thread is descheduled.
constexpr int kLcmQueueCapacity = 1000;
constexpr int kMaxBatch = 256;
// Channels (and loops) a status may list: a 256 x 256 plant.
constexpr std::uint32_t kMaxStatusItems = 65536;

class LcmTransport final : public Transport {
 public:
  explicit LcmTransport(const LcmSettings& settings)
      : settings_(settings), lcm_(lcm_create(settings.url.c_str())) {}
  ~LcmTransport() override {
    if (lcm_ != nullptr) lcm_destroy(lcm_);
  }
  LcmTransport(const LcmTransport&) = delete;
  LcmTransport& operator=(const LcmTransport&) = delete;

  bool good() const { return lcm_ != nullptr; }

  bool subscribe_samples(SampleHandler handler) override {
    return subscribe(settings_.sample_channel, on_sample_, std::move(handler), routes_[0],
                     &LcmTransport::receive_sample);
  }
  bool subscribe_alarms(AlarmHandler handler) override {
    return subscribe(settings_.alarm_channel, on_alarm_, std::move(handler), routes_[1], &LcmTransport::receive_alarm);
  }
  bool subscribe_status(StatusHandler handler) override {
    return subscribe(settings_.status_channel, on_status_, std::move(handler), routes_[2],
                     &LcmTransport::receive_status);
  }
  bool subscribe_diagnoses(DiagnosisHandler handler) override {
    return subscribe(settings_.diagnosis_channel, on_diagnosis_, std::move(handler), routes_[3],
                     &LcmTransport::receive_diagnosis);
  }

  bool publish(const msg::Sample& sample) override { return send(settings_.sample_channel, sample, tx_sample_); }
  bool publish(const msg::Alarm& alarm) override { return send(settings_.alarm_channel, alarm, tx_alarm_); }
  bool publish(const msg::Status& status) override { return send(settings_.status_channel, status, tx_status_); }
  bool publish(const msg::Diagnosis& diagnosis) override {
    return send(settings_.diagnosis_channel, diagnosis, tx_diagnosis_);
  }

  // lcm's handleTimeout dispatches one message; drain what is already waiting
  // on the descriptor too, up to a batch.
  int handle(std::chrono::milliseconds timeout) override {
    const int rc = lcm_handle_timeout(lcm_, static_cast<int>(timeout.count()));
    if (rc < 0) return errno == EINTR ? 0 : -1;  // a signal is not a failure
    if (rc == 0) return 0;
    int handled = 1;
    while (handled < kMaxBatch && readable_now()) {
      if (lcm_handle(lcm_) != 0) return -1;
      ++handled;
    }
    return handled;
  }

  int fd() const override { return lcm_get_fileno(lcm_); }
  std::uint64_t receive_errors() const override { return receive_errors_; }
  std::string describe() const override { return "lcm " + settings_.url; }

 private:
  using Receive = void (LcmTransport::*)(const lcm_recv_buf_t*);
  // What LCM's C callback gets as user data: this transport and the member
  // that decodes the channel's type.
  struct Route {
    LcmTransport* self = nullptr;
    Receive receive = nullptr;
  };
  static void dispatch(const lcm_recv_buf_t* rbuf, const char*, void* user) {
    const Route* r = static_cast<const Route*>(user);
    (r->self->*r->receive)(rbuf);
  }

  // `handler` kept in `slot`, then `channel` subscribed with `decode` as its
  // receiver (LCM calls it back only from handle(), so the order is free).
  template <typename Handler>
  bool subscribe(const std::string& channel, Handler& slot, Handler handler, Route& route, Receive decode) {
    slot = std::move(handler);
    route = Route{this, decode};
    lcm_subscription_t* sub = lcm_subscribe(lcm_, channel.c_str(), &LcmTransport::dispatch, &route);
    if (sub == nullptr) return false;
    lcm_subscription_set_queue_capacity(sub, kLcmQueueCapacity);
    return true;
  }

  bool readable_now() {
    pollfd p{lcm_get_fileno(lcm_), POLLIN, 0};
    return ::poll(&p, 1, 0) > 0 && (p.revents & POLLIN);
  }

  // `message` encoded through its lcm-gen struct `wire` (kept, so its
  // arrays keep their capacity) and published on `channel`.
  template <typename Plain, typename Wire>
  bool send(const std::string& channel, const Plain& message, Wire& wire) {
    std::lock_guard lock(publish_mutex_);
    lcm_codec::to_wire(message, wire);
    const int size = wire.getEncodedSize();
    if (size < 0) return false;
    tx_buffer_.resize(static_cast<std::size_t>(size));
    if (wire.encode(tx_buffer_.data(), 0, size) != size) return false;
    return lcm_publish(lcm_, channel.c_str(), tx_buffer_.data(), static_cast<unsigned>(size)) == 0;
  }

  // Alarms and status (mpm listen): our walk checks every length against the
  // bytes first (lcm_wire.hpp), then the generated decoder, which is safe on
  // checked bytes; a message that fails is counted and dropped.
  template <typename Wire, typename Plain, typename Handler>
  void receive(const lcm_recv_buf_t* rbuf, WireError checked, Wire& wire, Plain& plain, const Handler& handler) {
    bool ok = false;
    try {
      ok = checked == WireError::kNone && wire.decode(rbuf->data, 0, static_cast<int>(rbuf->data_size)) >= 0 &&
           lcm_codec::from_wire(wire, plain);
    } catch (const std::exception&) {
      ok = false;
    }
    if (!ok) {
      ++receive_errors_;
      return;
    }
    if (handler) handler(plain);
  }

  // Samples never reach the generated decoder: ours checks every length
  // against the bytes and the plant's dimensions before it writes.
  void receive_sample(const lcm_recv_buf_t* rbuf) {
    WireError error = WireError::kNone;
    try {
      error = decode_lcm_sample(rbuf->data, rbuf->data_size, sample_limits(), sample_);
    } catch (const std::exception&) {  // bad_alloc while first sizing the message
      error = WireError::kTruncated;
    }
    if (error != WireError::kNone) {
      ++receive_errors_;
      return;
    }
    if (on_sample_) on_sample_(sample_);
  }
  void receive_alarm(const lcm_recv_buf_t* rbuf) {
    const auto checked = check_lcm_alarm(rbuf->data, rbuf->data_size, sample_limits().max_string);
    receive(rbuf, checked, rx_alarm_, alarm_, on_alarm_);
  }
  void receive_status(const lcm_recv_buf_t* rbuf) {
    const SampleLimits limits = sample_limits();
    const auto checked = check_lcm_status(rbuf->data, rbuf->data_size, limits.max_string, kMaxStatusItems);
    // Cleared: LCM 1.3 does not resize a zero-length array, so an empty list
    // would keep the previous message's items.
    rx_status_.channels.clear();
    rx_status_.loops.clear();
    receive(rbuf, checked, rx_status_, status_, on_status_);
  }
  void receive_diagnosis(const lcm_recv_buf_t* rbuf) {
    const SampleLimits limits = sample_limits();
    const auto checked = check_lcm_diagnosis(rbuf->data, rbuf->data_size, limits.max_string, kMaxStatusItems);
    rx_diagnosis_ = {};  // fresh each time: LCM 1.3 does not clear zero-length arrays
    receive(rbuf, checked, rx_diagnosis_, diagnosis_, on_diagnosis_);
  }

  LcmSettings settings_;
  lcm_t* lcm_;
  Route routes_[4];  // samples, alarms, status, diagnoses: addresses handed to LCM

  SampleHandler on_sample_;
  AlarmHandler on_alarm_;
  StatusHandler on_status_;
  DiagnosisHandler on_diagnosis_;
  mpm_lcm::diagnosis_t rx_diagnosis_;
  msg::Diagnosis diagnosis_;
  mpm_lcm::alarm_t rx_alarm_;
  mpm_lcm::status_t rx_status_;
  msg::Sample sample_;
  msg::Alarm alarm_;
  msg::Status status_;
  std::atomic<std::uint64_t> receive_errors_{0};

  std::mutex publish_mutex_;
  mpm_lcm::sample_t tx_sample_;
  mpm_lcm::alarm_t tx_alarm_;
  mpm_lcm::status_t tx_status_;
  mpm_lcm::diagnosis_t tx_diagnosis_;
  std::vector<std::uint8_t> tx_buffer_;
};

}  // namespace

std::unique_ptr<Transport> make_lcm_transport(const LcmSettings& settings, std::string& error) {
  auto transport = std::make_unique<LcmTransport>(settings);
  if (!transport->good()) {
    error = "LCM: cannot open '" + settings.url +
            "' (a udpm:// URL needs a multicast route, e.g. 'ip route add 224.0.0.0/4 dev lo')";
    return nullptr;
  }
  return transport;
}

}  // namespace mpm::transport
