// The settings of the monitoring service of one controller (mpmd's
// MonitorService, and what `mpm monitor` replays with): the core monitor's
// settings plus the front end and data-quality ones. DaemonConfig (the whole
// mpmd.yaml) is these plus the file, transport and loop settings.
//
// Every setting is one row of a table (core/field_table.hpp): fields() for
// the top-level keys of mpmd.yaml, monitor_fields() for the `monitor:`
// section (MonitorSettings::fields() plus the rows below). A new setting is
// a member with its default here and one row in service_settings.cpp; the
// YAML reader, validation, reload comparison (operator==), the checkpoint's
// fingerprint, `mpm monitor`'s flags and the docs table follow from it.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "core/field_table.hpp"
#include "core/granger_monitor.hpp"

namespace mpm::config {

struct ServiceSettings {
  std::string controller_id;  // samples of other controllers are ignored
  MonitorSettings monitor;
  bool input_pole_auto = false;  // input_pole: auto = the plant's dominant pole
  // Regress on plain input lags (the paper's) instead of lags of the input
  // filtered through the nominal channel (what `mpm monitor` does by default).
  bool plain_lags = false;
  // Samples skipped after the nominal model starts (or restarts after a long
  // gap) while its start-up transient decays; -1 = the plant's settling time
  // (settle_length with kLiveSettleCap). `mpm monitor --settle-samples`.
  int settle_samples = -1;
  double log_interval = 60.0;  // seconds between repeats of one kind of log line
  // Largest sequence gap (or step back) taken as plausible; beyond it the
  // tracking resynchronises on the new number (SequenceTracker::kDefaultMaxJump).
  std::int64_t max_sequence_jump = 1000000;
  // Seconds without a usable sample after which the status says not ready;
  // -1 = automatic (the longer of 60 s and 10 sample times), 0 = never.
  double stale_after = -1.0;
  // Samples kept for the diagnosis of a raised output (diagnosis_worker.hpp);
  // 0 = no diagnosis.
  int diagnosis_window = 3000;
  // Usable samples between looks of the diagnosis scan over the last
  // diagnosis_window samples (needs diagnosis_window > 0); 0 = no scan. The
  // scan takes its share of monitor.detector.false_alarms_per_year
  // (share_rate, core/diagnosis_scan.hpp).
  int scan_interval = 500;

  // The `monitor:` section: MonitorSettings::fields() and the front end's rows.
  static const std::vector<FieldRow<ServiceSettings>>& monitor_fields();
  // The top-level keys (log_interval, ...).
  static const std::vector<FieldRow<ServiceSettings>>& fields();
  // Every setting out of its range, the monitor's first.
  std::vector<FieldError> errors() const;
  // Settings equal: a reload keeps the running statistics (with the same plant).
  bool operator==(const ServiceSettings&) const = default;
};

// Appends every row's key and value to `out` (a fingerprint of the settings:
// the checkpoint's, so a new row is in it without being named).
template <class S>
void append_values(const std::vector<FieldRow<S>>& rows, const S& s, std::string& out);

}  // namespace mpm::config
