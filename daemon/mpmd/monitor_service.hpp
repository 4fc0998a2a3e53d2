// The monitoring service of one controller, without any transport: samples in
// (plain messages), alarms out (a callback), status on request. It owns the
// core monitor by value (as PX4's bus wrapper owns its estimator), the
// residual generator of the nominal model, the sequence tracking and the
// data-quality counters. Unit tests drive it directly or through the fake
// transport; mpmd wires it to LCM or DDS.
//
// Per sample (on_sample): controller filter -> size check (a wrong-sized
// sample counts as malformed and never touches the sequence or session state)
// -> sequence check (duplicates and out-of-order samples dropped, gaps filled
// with missing samples so the model's time stays aligned, implausible jumps
// resynchronised) -> residual by the front end `mpm monitor` uses offline
// (core/monitor_front_end.hpp: u0, y - sim_y when the sample carries the
// controller's prediction, else y - G_M (u - u0), settling) -> monitor
// update -> alarm edges (AlarmEdges, alarm_facts: what `mpm monitor
// --events` prints) -> at a checkpoint of the diagnosis scan
// (core/diagnosis_scan.hpp), the last samples handed to the diagnosis
// thread, or the look skipped and counted when it is busy; its raises and
// clears are published between samples (poll_diagnoses). Every anomaly is counted for the status and logged
// through a Throttle (first at once, then at most once per log interval).
//
// Allocation: setup allocates; on_sample allocates nothing in steady state.
// Building an alarm message (rare: on a change) may grow its strings.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "config/service_settings.hpp"
#include "core/granger_monitor.hpp"
#include "core/mimo_model.hpp"
#include "core/monitor_front_end.hpp"
#include "core/plant_model.hpp"
#include "daemon/mpmd/diagnosis_worker.hpp"
#include "daemon/mpmd/sequence_tracker.hpp"
#include "daemon/mpmd/throttle.hpp"
#include "transport/messages.hpp"

namespace mpm {

// Its settings: one struct with mpmd.yaml's (config/service_settings.hpp).
using ServiceSettings = config::ServiceSettings;

struct ServiceCounters {
  std::uint64_t seen = 0;          // samples of this controller
  std::uint64_t gaps = 0;          // sequence gaps
  std::uint64_t missing = 0;       // samples lost in them
  std::uint64_t duplicates = 0;
  std::uint64_t out_of_order = 0;
  std::uint64_t restarts = 0;
  std::uint64_t jumps = 0;         // implausible sequence jumps, resynchronised (also in restarts)
  std::uint64_t malformed = 0;     // wrong sizes, plus bytes the transport could not decode
  std::uint64_t nan_samples = 0;
  std::uint64_t dropped = 0;       // lost before the service (receive queue full)
  std::uint64_t foreign = 0;       // samples of other controllers, ignored
  template <class V>
  void visit_state(V&& v) {  // checkpoint
    v(seen); v(gaps); v(missing); v(duplicates); v(out_of_order); v(restarts); v(malformed); v(nan_samples);
    v(dropped); v(foreign);
  }
};

class MonitorService {
 public:
  using AlarmSink = std::function<void(const msg::Alarm&)>;
  using Clock = Throttle::Clock;

  // Setup: allocates everything. Throws std::invalid_argument when the
  // settings are invalid for this plant.
  MonitorService(const PlantModel& plant, const ServiceSettings& settings, AlarmSink on_alarm);

  // One received sample (any controller). See the overview for the steps.
  void on_sample(const msg::Sample& sample, Clock::time_point now);

  // Samples lost before they reached the service, and messages the transport
  // could not decode: counted and logged (throttled).
  void add_dropped(std::uint64_t count, Clock::time_point now);
  void add_receive_errors(std::uint64_t count, Clock::time_point now);

  // Publishes a "cleared" alarm for every channel raised now, saying why (the
  // service is being replaced, e.g. by a reload with new settings), so that
  // operators do not keep seeing alarms nobody will clear.
  void retire(const std::string& reason);

  // Whether a usable sample came within `stale_after` of `now`; logs when
  // that changes, saying why. The status is not ready while stale. Call
  // before fill_status (the service loop does, every turn).
  void check_health(Clock::time_point now);
  bool stale() const noexcept { return stale_; }

  // Current statistics and counters. Reuses `out`'s storage.
  void fill_status(msg::Status& out, std::int64_t utime, std::int64_t uptime_ms) const;

  const ServiceCounters& counters() const noexcept { return counters_; }
  const GrangerMonitor& monitor() const noexcept { return monitor_; }
  const PlantModel& plant() const noexcept { return plant_; }
  const ServiceSettings& settings() const noexcept { return settings_; }
  int settle_samples() const noexcept { return front_.settle(); }
  std::int64_t last_sequence() const noexcept { return tracker_.last(); }
  const AlarmSink& alarm_sink() const noexcept { return on_alarm_; }

  // Main thread, between samples: hands over a pending diagnosis request and
  // passes each finished diagnosis to `publish`; the physics it names goes
  // into the channel's later alarm messages (the clear, a resume).
  // A finished look of the diagnosis scan publishes its raises and clears
  // as alarms (text "diagnosis scan: ...") and each raise's finding as a
  // diagnosis message.
  template <class Publish>
  void poll_diagnoses(Publish&& publish) {
    if (!diagnosis_) return;
    while (diagnosis_->take(diagnosis_msg_)) {
      if (diagnosis_msg_.found) physics_[static_cast<std::size_t>(diagnosis_msg_.output_index) * plant_.n_inputs() +
                                         static_cast<std::size_t>(diagnosis_msg_.input_index)] = diagnosis_msg_.physics;
      publish(diagnosis_msg_);
    }
    while (diagnosis_->take_look(look_result_)) {
      scan_.conclude(look_result_.flagged, [&](std::size_t j, bool raised) {
        publish_scan_alarm(j, raised);
        if (raised) publish(diagnosis_msg_);
      });
    }
  }
  const DiagnosisScan& scan() const noexcept { return scan_; }
  const DiagnosisWorker* diagnosis() const noexcept { return diagnosis_.get(); }

  // Publishes a "raised" alarm again for every channel raised now, saying
  // why (the service resumed from a checkpoint): listeners that saw the
  // previous process die learn the alarm still stands.
  void republish_raised(const std::string& reason);

  // Calls v(member) for everything that changes after setup (checkpoint.hpp):
  // the residual model (its u0 found at the first complete sample when the
  // plant file gives no operating point), the sequence, counters, settling
  // and alarm states, and the monitor. Throttles start afresh.
  template <class V>
  void visit_state(V&& v) {
    front_.visit_model(v);
    v(tracker_); v(counters_);
    front_.visit_settling(v);
    v(edges_); v(monitor_);
  }

 private:
  bool sized_right(const msg::Sample& s) const noexcept;
  void skip_missing(std::int64_t count) noexcept;
  void step(const double* u, const double* y, const double* sim_y) noexcept;
  void check_alarms(const msg::Sample& s);
  void publish_alarm(std::size_t output, std::size_t input, const msg::Sample& s);
  // A raise or clear of an output by the scan's last look (look_result_);
  // a raise leaves its finding's diagnosis message in diagnosis_msg_.
  void publish_scan_alarm(std::size_t output, bool raised);
  void start_look(const msg::Sample& s);
  void fill_alarm_header(std::size_t output, std::size_t input, std::int64_t utime, std::int64_t seq);
  // The header and the channel's whole-record F, p and gamma, stamped with
  // the last sequence number (a republished or retired alarm).
  void fill_channel_alarm(std::size_t output, std::size_t input, bool raised);
  void report_sequence(const SequenceTracker::Result& r, const msg::Sample& s, std::int64_t previous_seq,
                       Clock::time_point now);
  void report_malformed(const msg::Sample& s, Clock::time_point now);

  PlantModel plant_;
  ServiceSettings settings_;
  AlarmSink on_alarm_;
  GrangerMonitor monitor_;
  ResidualFrontEnd front_;
  SequenceTracker tracker_;
  ServiceCounters counters_;
  std::uint64_t malformed_pending_ = 0;  // malformed since the last accepted sample: not gaps
  std::chrono::duration<double> stale_after_{0.0};  // 0 = never stale
  std::optional<Clock::time_point> last_usable_;    // last sample that reached the model, finite
  std::optional<Clock::time_point> watch_start_;    // first check_health: the clock before any sample
  bool stale_ = false;
  std::vector<double> residual_;
  std::vector<double> nan_u_, nan_y_;        // a missing sample
  AlarmEdges edges_;                         // as published
  msg::Alarm alarm_;
  std::unique_ptr<DiagnosisWorker> diagnosis_;  // null when diagnosis_window = 0
  std::vector<std::string> physics_;           // per channel: the last diagnosis' physics word
  std::vector<long> scan_input_;               // per output the scan has raised: its finding's input (-1: none)
  msg::Diagnosis diagnosis_msg_;
  DiagnosisScan scan_;                         // off without diagnosis_
  bool look_due_ = false;                      // a checkpoint passed in this sample's steps
  DiagnosisWorker::LookResult look_result_;

  struct Throttles {
    Throttle foreign, gap, duplicate, out_of_order, restart, jump, malformed, nan, dropped, receive_errors;
  } throttles_;
};

}  // namespace mpm
