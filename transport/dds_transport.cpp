// Cyclone DDS adapter (C API: Debian ships no C++ binding). One participant
// per transport; readers are attached to a waitset that handle() waits on;
// samples are taken on loan and converted into reused plain messages.
#include "transport/dds_transport.hpp"

#include <array>
#include <atomic>
#include <map>
#include <mutex>
#include <type_traits>

#include <dds/dds.h>

#include "transport/dds_codec.hpp"
#include "transport/dds_qos.hpp"

namespace mpm::transport {

namespace {

constexpr int kMaxBatch = 64;

// Cyclone allows one explicit configuration per domain and process; several
// transports of one process (tests, a tool that both publishes and listens)
// share it. The domain lives while a transport uses it.
class DomainRegistry {
 public:
  static DomainRegistry& instance() {
    static DomainRegistry registry;
    return registry;
  }

  bool acquire(int domain, const std::string& config, std::string& error) {
    std::lock_guard lock(mutex_);
    auto& entry = domains_[domain];
    if (entry.users == 0 && !config.empty()) {
      const dds_entity_t handle = dds_create_domain(static_cast<dds_domainid_t>(domain), config.c_str());
      if (handle < 0 && handle != DDS_RETCODE_PRECONDITION_NOT_MET) {
        error = "DDS: cannot create domain " + std::to_string(domain) + " with configuration '" + config +
                "': " + dds_strretcode(handle);
        domains_.erase(domain);
        return false;
      }
      entry.handle = handle > 0 ? handle : 0;
    }
    ++entry.users;
    return true;
  }

  void release(int domain) {
    std::lock_guard lock(mutex_);
    auto it = domains_.find(domain);
    if (it == domains_.end() || --it->second.users > 0) return;
    if (it->second.handle > 0) dds_delete(it->second.handle);
    domains_.erase(it);
  }

 private:
  struct Entry {
    dds_entity_t handle = 0;  // 0 = implicit domain (Cyclone's default config)
    int users = 0;
  };
  std::mutex mutex_;
  std::map<int, Entry> domains_;
};

// A plain path becomes a file:// URI; URIs and inline XML pass through.
std::string config_uri(const std::string& config) {
  if (config.empty() || config.front() == '<' || config.rfind("file://", 0) == 0) return config;
  return "file://" + config;
}

class QosHolder {
 public:
  explicit QosHolder(dds_qos_t* qos) : qos_(qos) {}
  ~QosHolder() { dds_delete_qos(qos_); }
  QosHolder(const QosHolder&) = delete;
  QosHolder& operator=(const QosHolder&) = delete;
  const dds_qos_t* get() const { return qos_; }

 private:
  dds_qos_t* qos_;
};

class DdsTransport final : public Transport {
 public:
  explicit DdsTransport(const DdsSettings& settings) : settings_(settings) {}

  ~DdsTransport() override {
    if (participant_ > 0) dds_delete(participant_);  // deletes readers, writers, waitset
    if (domain_acquired_) DomainRegistry::instance().release(settings_.domain);
  }

  bool init(std::string& error) {
    if (!DomainRegistry::instance().acquire(settings_.domain, config_uri(settings_.config), error)) return false;
    domain_acquired_ = true;
    participant_ = dds_create_participant(static_cast<dds_domainid_t>(settings_.domain), nullptr, nullptr);
    if (participant_ < 0) return fail(error, "create a participant in domain", participant_);
    waitset_ = dds_create_waitset(participant_);
    if (waitset_ < 0) return fail(error, "create a waitset", waitset_);
    return true;
  }

  bool subscribe_samples(SampleHandler handler) override {
    return subscribe(sample_topic(), dds_qos::sample(settings_.sample_history), sample_reader_, on_sample_,
                     std::move(handler));
  }
  bool subscribe_alarms(AlarmHandler handler) override {
    return subscribe(alarm_topic(), dds_qos::alarm_reader(), alarm_reader_, on_alarm_, std::move(handler));
  }
  bool subscribe_status(StatusHandler handler) override {
    return subscribe(status_topic(), dds_qos::status_reader(), status_reader_, on_status_, std::move(handler));
  }
  // Diagnoses travel with the alarms' QoS (reliable, transient-local).
  bool subscribe_diagnoses(DiagnosisHandler handler) override {
    return subscribe(diagnosis_topic(), dds_qos::alarm_reader(), diagnosis_reader_, on_diagnosis_,
                     std::move(handler));
  }

  bool advertise(Topic topic) override {
    std::lock_guard lock(publish_mutex_);
    return writer(topic) > 0;
  }

  bool publish(const msg::Sample& sample) override { return write<mpm_dds_Sample>(Topic::kSample, sample); }
  bool publish(const msg::Alarm& alarm) override { return write<mpm_dds_Alarm>(Topic::kAlarm, alarm); }
  bool publish(const msg::Status& status) override { return write<mpm_dds_Status>(Topic::kStatus, status); }
  bool publish(const msg::Diagnosis& diagnosis) override {
    return write<mpm_dds_Diagnosis>(Topic::kDiagnosis, diagnosis);
  }

  int handle(std::chrono::milliseconds timeout) override {
    const dds_return_t rc = dds_waitset_wait(waitset_, nullptr, 0, DDS_MSECS(timeout.count()));
    if (rc < 0) return -1;
    if (rc == 0) return 0;
    int handled = 0;
    if (sample_reader_ > 0) handled += take<mpm_dds_Sample>(sample_reader_, sample_, on_sample_);
    if (alarm_reader_ > 0) handled += take<mpm_dds_Alarm>(alarm_reader_, alarm_, on_alarm_);
    if (status_reader_ > 0) handled += take<mpm_dds_Status>(status_reader_, status_, on_status_);
    if (diagnosis_reader_ > 0) handled += take<mpm_dds_Diagnosis>(diagnosis_reader_, diagnosis_, on_diagnosis_);
    return handled;
  }

  bool wait_for_sample_readers(int count, std::chrono::milliseconds timeout) override {
    dds_entity_t w = 0;
    {
      std::lock_guard lock(publish_mutex_);
      w = writer(Topic::kSample);
    }
    if (w <= 0) return false;
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    for (;;) {
      dds_publication_matched_status_t status{};
      if (dds_get_publication_matched_status(w, &status) == DDS_RETCODE_OK &&
          static_cast<int>(status.current_count) >= count) {
        return true;
      }
      if (std::chrono::steady_clock::now() >= deadline) return false;
      dds_sleepfor(DDS_MSECS(10));
    }
  }

  bool flush(std::chrono::milliseconds timeout) override {
    std::lock_guard lock(publish_mutex_);
    bool ok = true;
    for (const dds_entity_t w : {sample_writer_, alarm_writer_, status_writer_, diagnosis_writer_}) {
      if (w > 0) ok = dds_wait_for_acks(w, DDS_MSECS(timeout.count())) == DDS_RETCODE_OK && ok;
    }
    return ok;
  }

  int fd() const override { return -1; }
  std::uint64_t receive_errors() const override { return receive_errors_; }
  std::string describe() const override {
    return "dds domain " + std::to_string(settings_.domain) +
           (settings_.config.empty() ? std::string() : " config " + settings_.config);
  }

 private:
  static bool fail(std::string& error, const char* what, dds_return_t rc) {
    error = std::string("DDS: cannot ") + what + ": " + dds_strretcode(rc);
    return false;
  }

  // Topics are made on first use, from the receiver's or a publisher's thread.
  dds_entity_t topic(dds_entity_t& cached, const dds_topic_descriptor_t* descriptor, const std::string& name) {
    std::lock_guard lock(topic_mutex_);
    if (cached <= 0) cached = dds_create_topic(participant_, descriptor, name.c_str(), nullptr, nullptr);
    return cached;
  }
  dds_entity_t sample_topic() { return topic(sample_topic_, &mpm_dds_Sample_desc, settings_.sample_topic); }
  dds_entity_t alarm_topic() { return topic(alarm_topic_, &mpm_dds_Alarm_desc, settings_.alarm_topic); }
  dds_entity_t status_topic() { return topic(status_topic_, &mpm_dds_Status_desc, settings_.status_topic); }
  dds_entity_t diagnosis_topic() {
    return topic(diagnosis_topic_, &mpm_dds_Diagnosis_desc, settings_.diagnosis_topic);
  }

  // A reader of `topic` with `qos` (owned here), whose messages go to `slot`.
  template <typename Handler>
  bool subscribe(dds_entity_t topic, dds_qos_t* qos, dds_entity_t& reader, Handler& slot, Handler handler) {
    const QosHolder holder(qos);
    if (!add_reader(topic, holder.get(), reader)) return false;
    slot = std::move(handler);
    return true;
  }

  // `message` on its topic's writer. The wire struct is a view into the
  // message and scratch_ (an alarm has no sequence, so no scratch).
  template <typename Wire, typename Plain>
  bool write(Topic topic, const Plain& message) {
    std::lock_guard lock(publish_mutex_);
    const dds_entity_t w = writer(topic);
    if (w <= 0) return false;
    Wire wire{};
    if constexpr (std::is_same_v<Plain, msg::Alarm>) {
      dds_codec::to_wire(message, wire);
    } else {
      dds_codec::to_wire(message, wire, scratch_);
    }
    return dds_write(w, &wire) == DDS_RETCODE_OK;
  }

  bool add_reader(dds_entity_t topic, const dds_qos_t* qos, dds_entity_t& reader) {
    if (topic <= 0 || reader > 0) return false;
    const dds_entity_t r = dds_create_reader(participant_, topic, qos, nullptr);
    if (r < 0) return false;
    const dds_entity_t condition = dds_create_readcondition(r, DDS_ANY_STATE);
    if (condition < 0 || dds_waitset_attach(waitset_, condition, r) < 0) {
      dds_delete(r);
      return false;
    }
    reader = r;
    return true;
  }

  // Caller holds publish_mutex_.
  dds_entity_t writer(Topic which) {
    switch (which) {
      case Topic::kSample: {
        if (sample_writer_ > 0) return sample_writer_;
        const QosHolder qos(dds_qos::sample(settings_.sample_history));
        return sample_writer_ = make_writer(sample_topic(), qos.get());
      }
      case Topic::kAlarm: {
        if (alarm_writer_ > 0) return alarm_writer_;
        const QosHolder qos(dds_qos::alarm_writer());
        return alarm_writer_ = make_writer(alarm_topic(), qos.get());
      }
      case Topic::kStatus: {
        if (status_writer_ > 0) return status_writer_;
        const QosHolder qos(dds_qos::status_writer());
        return status_writer_ = make_writer(status_topic(), qos.get());
      }
      case Topic::kDiagnosis: {
        if (diagnosis_writer_ > 0) return diagnosis_writer_;
        const QosHolder qos(dds_qos::alarm_writer());
        return diagnosis_writer_ = make_writer(diagnosis_topic(), qos.get());
      }
    }
    return 0;
  }

  dds_entity_t make_writer(dds_entity_t topic, const dds_qos_t* qos) {
    if (topic <= 0) return 0;
    const dds_entity_t w = dds_create_writer(participant_, topic, qos, nullptr);
    return w > 0 ? w : 0;
  }

  // Samples are checked against the limits before they are copied; alarms and
  // status come from Cyclone's checked deserialiser into messages of our own.
  bool convert(const mpm_dds_Sample& wire, msg::Sample& plain) {
    return dds_codec::from_wire(wire, sample_limits(), plain) == WireError::kNone;
  }
  template <typename Wire, typename Plain>
  bool convert(const Wire& wire, Plain& plain) {
    dds_codec::from_wire(wire, plain);
    return true;
  }

  // Takes a batch on loan, converts each valid sample and hands it on.
  template <typename Wire, typename Plain, typename Handler>
  int take(dds_entity_t reader, Plain& plain, const Handler& handler) {
    std::array<void*, kMaxBatch> samples{};
    std::array<dds_sample_info_t, kMaxBatch> infos{};
    const dds_return_t n = dds_take(reader, samples.data(), infos.data(), kMaxBatch, kMaxBatch);
    if (n < 0) {
      ++receive_errors_;
      return 0;
    }
    int handled = 0;
    for (dds_return_t i = 0; i < n; ++i) {
      if (!infos[static_cast<std::size_t>(i)].valid_data) continue;  // dispose / unregister notices
      if (!convert(*static_cast<const Wire*>(samples[static_cast<std::size_t>(i)]), plain)) {
        ++receive_errors_;
        continue;
      }
      if (handler) handler(plain);
      ++handled;
    }
    dds_return_loan(reader, samples.data(), n);
    return handled;
  }

  DdsSettings settings_;
  bool domain_acquired_ = false;
  dds_entity_t participant_ = 0;
  dds_entity_t waitset_ = 0;
  std::mutex topic_mutex_;
  dds_entity_t sample_topic_ = 0, alarm_topic_ = 0, status_topic_ = 0;
  dds_entity_t sample_reader_ = 0, alarm_reader_ = 0, status_reader_ = 0;
  dds_entity_t diagnosis_topic_ = 0, diagnosis_reader_ = 0, diagnosis_writer_ = 0;
  DiagnosisHandler on_diagnosis_;
  msg::Diagnosis diagnosis_;

  SampleHandler on_sample_;
  AlarmHandler on_alarm_;
  StatusHandler on_status_;
  msg::Sample sample_;
  msg::Alarm alarm_;
  msg::Status status_;
  std::atomic<std::uint64_t> receive_errors_{0};

  std::mutex publish_mutex_;
  dds_entity_t sample_writer_ = 0, alarm_writer_ = 0, status_writer_ = 0;
  dds_codec::Scratch scratch_;
};

}  // namespace

std::unique_ptr<Transport> make_dds_transport(const DdsSettings& settings, std::string& error) {
  auto transport = std::make_unique<DdsTransport>(settings);
  if (!transport->init(error)) return nullptr;
  return transport;
}

}  // namespace mpm::transport
