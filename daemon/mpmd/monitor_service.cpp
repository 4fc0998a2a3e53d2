#include "daemon/mpmd/monitor_service.hpp"

#include <algorithm>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <limits>

#include "daemon/mpmd/log.hpp"

namespace mpm {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// A gap longer than this restarts the settle time: the model held the last
// input through it while the plant saw the real ones, and that error decays
// like a start-up transient. Shorter gaps leave a negligible error.
constexpr std::int64_t kResettleGap = 5;
// Missing samples fed through the model for one gap at most; beyond, the
// model's time is lost anyway and the settle restart covers it.
constexpr std::int64_t kMaxGapFill = 10000;

bool all_finite(const std::vector<double>& v) noexcept {
  for (const double x : v) {
    if (!std::isfinite(x)) return false;
  }
  return true;
}

std::int64_t unix_micros() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

std::chrono::duration<double> seconds(double s) { return std::chrono::duration<double>(s); }

// " (N more since the last report)" or "".
struct Suppressed {
  explicit Suppressed(const Throttle& t) {
    if (t.suppressed() == 0) {
      text[0] = '\0';
    } else {
      std::snprintf(text, sizeof text, " (%" PRIu64 " more since the last report)", t.suppressed());
    }
  }
  char text[64];
};

// The scan as `mpm monitor --events` runs it: over the diagnosis window,
// every scan_interval usable samples.
ScanSettings scan_settings(const ServiceSettings& s) {
  ScanSettings scan;
  scan.window = static_cast<std::size_t>(std::max(0, s.diagnosis_window));
  scan.interval = s.diagnosis_window > 0 ? static_cast<std::size_t>(std::max(0, s.scan_interval)) : 0;
  scan.min_samples = std::min(scan.min_samples, scan.window);
  return scan;
}

// The monitor's settings with the sequential detector's share of the rate.
MonitorSettings sequential_share(const PlantModel& plant, const ServiceSettings& s) {
  MonitorSettings m = s.monitor;
  if (const std::string e = scan_settings(s).validate(); !e.empty()) throw std::invalid_argument(e);
  share_rate(m.detector, scan_settings(s), plant.sample_time);
  return m;
}

// The samples the live front end skips at the start (the monitor's first
// start follows it: MonitorBlueprint::build).
std::size_t live_settle(const PlantModel& plant, const ServiceSettings& s) {
  return settle_length(plant, s.settle_samples, kLiveSettleCap);
}

}  // namespace

MonitorService::MonitorService(const PlantModel& plant, const ServiceSettings& settings, AlarmSink on_alarm)
    : plant_(plant),
      settings_(settings),
      on_alarm_(std::move(on_alarm)),
      // The same monitor and front end as `mpm monitor` builds offline.
      monitor_(MonitorBlueprint(plant, sequential_share(plant, settings), settings.plain_lags)
                   .build({}, live_settle(plant, settings))),
      front_(plant, live_settle(plant, settings)),
      tracker_(settings.max_sequence_jump),
      residual_(plant.n_outputs(), 0.0),
      nan_u_(plant.n_inputs(), kNaN),
      nan_y_(plant.n_outputs(), kNaN),
      edges_(plant.n_outputs(), plant.n_inputs()),
      physics_(plant.n_inputs() * plant.n_outputs()),
      scan_input_(plant.n_outputs(), -1) {
  if (settings.diagnosis_window > 0) {
    diagnosis_ = std::make_unique<DiagnosisWorker>(plant, static_cast<std::size_t>(settings.diagnosis_window));
    const ScanSettings scan = scan_settings(settings);
    DetectorSettings whole = settings.monitor.detector;
    scan_ = DiagnosisScan(plant.n_outputs(), scan, share_rate(whole, scan, plant.sample_time));
  }
  const auto interval = seconds(settings.log_interval);
  const double auto_stale = std::max(60.0, 10.0 * plant.sample_time);
  stale_after_ = seconds(settings.stale_after < 0 ? auto_stale : settings.stale_after);
  for (Throttle* t : {&throttles_.foreign, &throttles_.gap, &throttles_.duplicate, &throttles_.out_of_order,
                      &throttles_.restart, &throttles_.jump, &throttles_.malformed, &throttles_.nan,
                      &throttles_.dropped,
                      &throttles_.receive_errors}) {
    t->set_interval(interval);
  }
}

void MonitorService::on_sample(const msg::Sample& s, Clock::time_point now) {
  if (s.controller_id != settings_.controller_id) {
    ++counters_.foreign;
    if (throttles_.foreign.event(now)) {
      log::write(log::Level::kInfo, "ignoring samples of controller '%s' (this monitor watches '%s')%s",
                 s.controller_id.c_str(), settings_.controller_id.c_str(), Suppressed(throttles_.foreign).text);
    }
    return;
  }
  ++counters_.seen;
  // Sizes first: a malformed sample's numbers are not trusted, so it never
  // moves the sequence or the session (the hole it leaves is filled when the
  // next good sample arrives).
  if (!sized_right(s)) {
    report_malformed(s, now);
    ++malformed_pending_;
    return;
  }
  const std::int64_t previous_seq = tracker_.last();
  const SequenceTracker::Result r = tracker_.observe(s.session_id, s.seq);
  report_sequence(r, s, previous_seq, now);
  switch (r.verdict) {
    case SequenceTracker::Verdict::kDuplicate:
    case SequenceTracker::Verdict::kOutOfOrder:
      return;
    case SequenceTracker::Verdict::kGap:
      skip_missing(r.missing);
      break;
    case SequenceTracker::Verdict::kRestart:
    case SequenceTracker::Verdict::kJump:
      skip_missing(kResettleGap + 1);  // unknown gap: break the lags, settle again
      break;
    default:
      break;
  }
  malformed_pending_ = 0;
  const bool finite = all_finite(s.u) && all_finite(s.y) && all_finite(s.sim_y);
  if (finite) last_usable_ = now;
  if (!finite) {
    ++counters_.nan_samples;
    if (throttles_.nan.event(now)) {
      log::write(log::Level::kWarning,
                 "controller '%s': sample %" PRId64 " carries NaN or infinite values: treated as missing "
                 "(%" PRIu64 " such samples so far)%s",
                 s.controller_id.c_str(), s.seq, counters_.nan_samples, Suppressed(throttles_.nan).text);
    }
  }
  step(s.u.data(), s.y.data(), s.sim_y.empty() ? nullptr : s.sim_y.data());
  check_alarms(s);
  if (look_due_) start_look(s);
}

// A checkpoint of the scan: the last samples to the diagnosis thread, or the
// look skipped (counted) while it is busy: nothing waits for it.
void MonitorService::start_look(const msg::Sample& s) {
  look_due_ = false;
  const std::int64_t utime = s.utime != 0 ? s.utime : unix_micros();
  if (diagnosis_->look({scan_.look_length(), scan_.alpha_look(), utime, s.seq})) return;
  scan_.skip();
  log::write(log::Level::kWarning,
             "controller '%s': diagnosis scan look at sample %" PRId64 " skipped: the diagnosis thread is busy "
             "(%" PRIu64 " skipped so far)",
             settings_.controller_id.c_str(), s.seq, scan_.skipped());
}

void MonitorService::publish_scan_alarm(std::size_t output, bool raised) {
  const DiagnosisWorker::LookResult& r = look_result_;
  // The finding's input on the output (-1: none, e.g. a disturbance model).
  const long input = raised && r.inputs[output] ? static_cast<long>(*r.inputs[output]) : -1;
  scan_input_[output] = input;
  alarm_.controller_id = settings_.controller_id;
  alarm_.utime = r.look.utime;
  alarm_.sample_sequence = r.look.seq;
  alarm_.output = plant_.outputs[output];
  alarm_.input = input >= 0 ? plant_.inputs[static_cast<std::size_t>(input)] : std::string();
  alarm_.output_index = static_cast<std::int32_t>(output);
  alarm_.input_index = static_cast<std::int32_t>(input);
  alarm_.raised = raised;
  alarm_.f = kNaN;
  alarm_.p_value = r.look.alpha;  // the look's level
  alarm_.gamma = kNaN;
  if (raised) {
    diagnosis_msg_ = r.findings[output];
    diagnosis_msg_.controller_id = settings_.controller_id;
    diagnosis_msg_.utime = r.look.utime;
    diagnosis_msg_.sample_sequence = r.look.seq;
    diagnosis_msg_.output = alarm_.output;
    diagnosis_msg_.input = alarm_.input;
    diagnosis_msg_.output_index = alarm_.output_index;
    diagnosis_msg_.input_index = alarm_.input_index;
    diagnosis_msg_.window = static_cast<std::int32_t>(r.look.rows);
    alarm_.physics = diagnosis_msg_.physics;
    alarm_.text = "diagnosis scan: raised " + alarm_.output + ": " + diagnosis_msg_.text;
    if (input >= 0) physics_[output * plant_.n_inputs() + static_cast<std::size_t>(input)] = diagnosis_msg_.physics;
  } else {
    alarm_.physics.clear();
    alarm_.text = "diagnosis scan: cleared " + alarm_.output + ": no finding on it in " +
                  std::to_string(scan_.settings().clear_after) + " looks in a row";
  }
  log::write(raised ? log::Level::kWarning : log::Level::kNotice, "controller '%s': %s",
             settings_.controller_id.c_str(), alarm_.text.c_str());
  if (on_alarm_) on_alarm_(alarm_);
}

bool MonitorService::sized_right(const msg::Sample& s) const noexcept {
  return s.u.size() == plant_.n_inputs() && s.y.size() == plant_.n_outputs() &&
         (s.sim_y.empty() || s.sim_y.size() == plant_.n_outputs());
}

void MonitorService::skip_missing(std::int64_t count) noexcept {
  const std::int64_t fill = count < kMaxGapFill ? count : kMaxGapFill;
  for (std::int64_t k = 0; k < fill; ++k) step(nan_u_.data(), nan_y_.data(), nullptr);
  if (count > kResettleGap) front_.resettle();
}

// Residual of one sample (NaN where values are missing), then the monitor.
void MonitorService::step(const double* u, const double* y, const double* sim_y) noexcept {
  switch (front_.step(u, y, sim_y, residual_.data())) {
    case ResidualFrontEnd::Stage::kNoOrigin:
      return;  // no operating point yet: waits for a complete input sample
    case ResidualFrontEnd::Stage::kSettling:
      if (diagnosis_) diagnosis_->record(u, nan_y_.data());  // the transient is not evidence
      scan_.restart();  // the scan's window grows from the first settled sample
      return;
    case ResidualFrontEnd::Stage::kReady:
      break;
  }
  if (diagnosis_) diagnosis_->record(u, residual_.data());
  monitor_.update(u, residual_.data());
  if (scan_.on_ready_sample()) look_due_ = true;
}

void MonitorService::check_alarms(const msg::Sample& s) {
  edges_.scan(monitor_, [&](std::size_t j, std::size_t i, bool raised) {
    // A new episode: its physics is not known yet, unless the scan has this
    // output raised with a finding on this very channel (the same episode,
    // its word already found).
    const bool scan_named_it = scan_.enabled() && scan_.raised(j) && scan_input_[j] == static_cast<long>(i);
    if (raised && !scan_named_it) physics_[j * plant_.n_inputs() + i].clear();
    publish_alarm(j, i, s);
    if (raised && diagnosis_) diagnosis_->request({j, i, alarm_.utime, s.seq, settings_.controller_id});
  });
}

void MonitorService::fill_alarm_header(std::size_t output, std::size_t input, std::int64_t utime, std::int64_t seq) {
  alarm_.controller_id = settings_.controller_id;
  // The sample's own time; the time of receipt when the publisher sent none.
  alarm_.utime = utime != 0 ? utime : unix_micros();
  alarm_.sample_sequence = seq;
  alarm_.output = plant_.outputs[output];
  alarm_.input = plant_.inputs[input];
  alarm_.output_index = static_cast<std::int32_t>(output);
  alarm_.input_index = static_cast<std::int32_t>(input);
}

void MonitorService::fill_channel_alarm(std::size_t output, std::size_t input, bool raised) {
  const ChannelStats& c = monitor_.channel(output, input);
  fill_alarm_header(output, input, 0, tracker_.last());
  alarm_.raised = raised;
  alarm_.f = c.f_conditional;
  alarm_.p_value = monitor_.p_value(c.lr_conditional);
  alarm_.gamma = c.gamma;
}

void MonitorService::republish_raised(const std::string& reason) {
  const std::size_t n_in = plant_.n_inputs();
  for (std::size_t j = 0; j < plant_.n_outputs(); ++j) {
    for (std::size_t i = 0; i < n_in; ++i) {
      if (!edges_.raised(j, i)) continue;
      fill_channel_alarm(j, i, true);
      alarm_.physics = physics_[j * n_in + i];
      alarm_.text = "still raised: model-plant mismatch on " + alarm_.input + " -> " + alarm_.output + " (" +
                    reason + ")";
      log::write(log::Level::kWarning, "controller '%s': %s", settings_.controller_id.c_str(), alarm_.text.c_str());
      if (on_alarm_) on_alarm_(alarm_);
    }
  }
}

void MonitorService::retire(const std::string& reason) {
  const std::size_t n_in = plant_.n_inputs();
  // The scan's raised outputs too (their state is not carried over).
  for (std::size_t j = 0; j < plant_.n_outputs() && scan_.enabled(); ++j) {
    if (!scan_.raised(j)) continue;
    scan_.lower(j);
    fill_alarm_header(j, 0, 0, tracker_.last());
    alarm_.input.clear();
    alarm_.input_index = -1;
    alarm_.raised = false;
    alarm_.f = alarm_.gamma = kNaN;
    alarm_.p_value = scan_.alpha_look();
    alarm_.physics.clear();
    alarm_.text = "diagnosis scan: cleared " + alarm_.output + ": no longer watched by this monitor (" + reason + ")";
    log::write(log::Level::kNotice, "controller '%s': %s", settings_.controller_id.c_str(), alarm_.text.c_str());
    if (on_alarm_) on_alarm_(alarm_);
  }
  for (std::size_t j = 0; j < plant_.n_outputs(); ++j) {
    for (std::size_t i = 0; i < n_in; ++i) {
      if (!edges_.raised(j, i)) continue;
      edges_.lower(j, i);
      fill_channel_alarm(j, i, false);
      alarm_.physics.clear();
      alarm_.text = "cleared: " + alarm_.input + " -> " + alarm_.output + " no longer watched by this monitor (" +
                    reason + ")";
      log::write(log::Level::kNotice, "controller '%s': %s", settings_.controller_id.c_str(), alarm_.text.c_str());
      if (on_alarm_) on_alarm_(alarm_);
    }
  }
}

void MonitorService::publish_alarm(std::size_t output, std::size_t input, const msg::Sample& s) {
  const AlarmFacts f = alarm_facts(monitor_, output, input);
  fill_alarm_header(output, input, s.utime, s.seq);
  alarm_.raised = f.raised;
  alarm_.f = f.f_conditional;
  alarm_.p_value = f.p_value;
  alarm_.gamma = f.gamma;
  // Known once the diagnosis that a raise asks for has finished: empty in the
  // raise itself (the diagnosis message follows it), filled in later alarms;
  // known at once when the scan has already named this channel.
  alarm_.physics = physics_[output * plant_.n_inputs() + input];
  char text[320];
  if (f.raised) {
    // The output's sequential detector raised; this channel has the best
    // evidence (its conditional score, or the paper's gamma rule). The
    // statistic and threshold to 10 digits: what `mpm monitor --events`
    // prints for the same samples (tests/daemon/loopback_events_test.cpp).
    std::snprintf(text, sizeof text,
                  "model-plant mismatch on %s -> %s: score %.10g > %.10g over %.0f samples, conditional score %.1f "
                  "(p=%.2g)%s, gamma=%.3g",
                  alarm_.input.c_str(), alarm_.output.c_str(), f.statistic, f.threshold, f.window,
                  f.conditional_score, f.p_value, f.by_gamma ? " named by gamma" : "", f.gamma);
  } else {
    std::snprintf(text, sizeof text, "cleared: %s -> %s agrees with the model again: F=%.4g",
                  alarm_.input.c_str(), alarm_.output.c_str(), f.f_conditional);
  }
  alarm_.text = text;
  log::write(f.raised ? log::Level::kWarning : log::Level::kNotice, "controller '%s': %s (sample %" PRId64 ")",
             settings_.controller_id.c_str(), text, s.seq);
  if (on_alarm_) on_alarm_(alarm_);
}

void MonitorService::report_sequence(const SequenceTracker::Result& r, const msg::Sample& s,
                                     std::int64_t previous_seq, Clock::time_point now) {
  using V = SequenceTracker::Verdict;
  const char* id = s.controller_id.c_str();
  switch (r.verdict) {
    case V::kGap: {
      // Samples that arrived malformed are counted there, not as missing.
      const auto missing = static_cast<std::uint64_t>(r.missing);
      if (missing <= malformed_pending_) break;
      ++counters_.gaps;
      counters_.missing += missing - malformed_pending_;
      if (throttles_.gap.event(now)) {
        log::write(log::Level::kWarning,
                   "controller '%s': %" PRId64 " samples missing before sample %" PRId64
                   " (gaps so far: %" PRIu64 ")%s",
                   id, static_cast<std::int64_t>(missing - malformed_pending_), s.seq, counters_.gaps,
                   Suppressed(throttles_.gap).text);
      }
      break;
    }
    case V::kJump:
      ++counters_.jumps;
      ++counters_.restarts;
      if (throttles_.jump.event(now)) {
        log::write(log::Level::kWarning,
                   "controller '%s': sequence jumped from %" PRId64 " to %" PRId64
                   " (more than max_sequence_jump %" PRId64 "): resynchronised on it, statistics kept "
                   "(jumps so far: %" PRIu64 ")%s",
                   id, previous_seq, s.seq, settings_.max_sequence_jump, counters_.jumps,
                   Suppressed(throttles_.jump).text);
      }
      break;
    case V::kDuplicate:
      ++counters_.duplicates;
      if (throttles_.duplicate.event(now)) {
        log::write(log::Level::kWarning, "controller '%s': duplicate of sample %" PRId64 " ignored%s", id, s.seq,
                   Suppressed(throttles_.duplicate).text);
      }
      break;
    case V::kOutOfOrder:
      ++counters_.out_of_order;
      if (throttles_.out_of_order.event(now)) {
        log::write(log::Level::kWarning,
                   "controller '%s': sample %" PRId64 " arrived after sample %" PRId64 ": ignored%s", id, s.seq,
                   previous_seq, Suppressed(throttles_.out_of_order).text);
      }
      break;
    case V::kRestart:
      ++counters_.restarts;
      if (throttles_.restart.event(now)) {
        log::write(log::Level::kNotice,
                   "controller '%s': publisher restarted (session %" PRId64 ", sample %" PRId64
                   "); statistics kept%s",
                   id, s.session_id, s.seq, Suppressed(throttles_.restart).text);
      }
      break;
    default:
      break;
  }
}

void MonitorService::report_malformed(const msg::Sample& s, Clock::time_point now) {
  ++counters_.malformed;
  if (!throttles_.malformed.event(now)) return;
  log::write(log::Level::kWarning,
             "controller '%s': sample %" PRId64 " has %zu inputs, %zu outputs, %zu simulated outputs; "
             "the plant has %zu inputs and %zu outputs: ignored (malformed so far: %" PRIu64 ")%s",
             s.controller_id.c_str(), s.seq, s.u.size(), s.y.size(), s.sim_y.size(), plant_.n_inputs(),
             plant_.n_outputs(), counters_.malformed, Suppressed(throttles_.malformed).text);
}

void MonitorService::add_dropped(std::uint64_t count, Clock::time_point now) {
  if (count == 0) return;
  counters_.dropped += count;
  if (throttles_.dropped.event(now)) {
    log::write(log::Level::kWarning,
               "receive queue full: %" PRIu64 " samples dropped so far (the monitor falls behind)%s",
               counters_.dropped, Suppressed(throttles_.dropped).text);
  }
}

void MonitorService::add_receive_errors(std::uint64_t count, Clock::time_point now) {
  if (count == 0) return;
  counters_.malformed += count;
  if (throttles_.receive_errors.event(now)) {
    log::write(log::Level::kWarning, "%" PRIu64 " messages could not be decoded (wrong type or bytes)%s", count,
               Suppressed(throttles_.receive_errors).text);
  }
}

void MonitorService::check_health(Clock::time_point now) {
  if (!watch_start_) watch_start_ = now;
  if (stale_after_.count() <= 0) return;
  const Clock::time_point since = last_usable_ ? *last_usable_ : *watch_start_;
  const bool stale = now - since > stale_after_;
  if (stale == stale_) return;
  stale_ = stale;
  const char* id = settings_.controller_id.c_str();
  if (!stale) {
    log::write(log::Level::kNotice, "controller '%s': usable samples again: status ready when warmed up", id);
    return;
  }
  const char* why = counters_.seen == 0 ? "no sample of this controller has arrived"
                    : last_usable_     ? "samples stopped, or none since was usable"
                                       : "samples arrive but none was usable";
  log::write(log::Level::kWarning,
             "controller '%s': no usable sample for more than %.0f s (stale_after): status not ready; %s "
             "(seen %" PRIu64 ", malformed %" PRIu64 ", NaN %" PRIu64 ", duplicates %" PRIu64
             ", out of order %" PRIu64 ")",
             id, stale_after_.count(), why, counters_.seen, counters_.malformed, counters_.nan_samples,
             counters_.duplicates, counters_.out_of_order);
}

void MonitorService::fill_status(msg::Status& out, std::int64_t utime, std::int64_t uptime_ms) const {
  const MonitorCounters& mc = monitor_.counters();
  out.controller_id = settings_.controller_id;
  out.utime = utime;
  out.uptime_ms = uptime_ms;
  out.ready = monitor_.ready() && !stale_;
  out.effective_samples = monitor_.effective_samples();
  // The live detector's levels (its first window's: the others are in the log).
  out.raise_threshold = monitor_.detector().threshold(0);
  out.clear_threshold = monitor_.detector().clear_level(0);
  out.samples_seen = static_cast<std::int64_t>(counters_.seen);
  out.samples_used = static_cast<std::int64_t>(mc.used);
  out.dropped = static_cast<std::int64_t>(counters_.dropped);
  out.gaps = static_cast<std::int64_t>(counters_.gaps);
  out.missing = static_cast<std::int64_t>(counters_.missing);
  out.duplicates = static_cast<std::int64_t>(counters_.duplicates);
  out.out_of_order = static_cast<std::int64_t>(counters_.out_of_order);
  out.restarts = static_cast<std::int64_t>(counters_.restarts);
  out.malformed = static_cast<std::int64_t>(counters_.malformed);
  out.nan_samples = static_cast<std::int64_t>(counters_.nan_samples);
  const std::size_t n_in = plant_.n_inputs();
  out.channels.resize(n_in * plant_.n_outputs());
  out.loops.resize(plant_.n_outputs());
  std::int64_t raised = 0;
  for (std::size_t j = 0; j < plant_.n_outputs(); ++j) {
    for (std::size_t i = 0; i < n_in; ++i) {
      const ChannelStats& c = monitor_.channel(j, i);
      msg::ChannelStatus& o = out.channels[j * n_in + i];
      o.output = plant_.outputs[j];
      o.input = plant_.inputs[i];
      o.f_pairwise = c.f_pairwise;
      o.f_conditional = c.f_conditional;
      o.lr = c.lr_conditional;
      o.p_value = monitor_.p_value(c.lr_conditional);
      o.gamma = c.gamma;
      o.alarm = c.alarm;
      raised += c.alarm ? 1 : 0;
    }
    const LoopStats& l = monitor_.loop(j);
    msg::LoopStatus& lo = out.loops[j];
    lo.output = plant_.outputs[j];
    lo.residual_variance = l.residual_variance;
    lo.sigma1 = l.sigma1;
    lo.sigma_full = l.sigma_full;
    lo.alarm = l.alarm || (scan_.enabled() && scan_.raised(j));
    lo.diverging = l.diverging;
  }
  out.alarms_raised = raised;
}

}  // namespace mpm
