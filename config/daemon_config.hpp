// The service configuration, mpmd.yaml: which controller to watch, its plant
// file, the monitor's settings and the transport. Every key but
// controller_id and plant is optional; defaults are those of MonitorSettings
// and transport::Settings. Errors name the file, line, key and what was
// expected (ConfigError), like the plant loader's.
//
//   controller_id: wood-berry-1
//   plant: wood-berry.yaml          # relative to this file's folder
//   monitor: {ar_order: 10, input_order: 10, forgetting: 0.999, false_alarm: 1e-3,
//             false_alarms_per_year: 1, sample_time: 0 (= the plant's),
//             crossing_constant: 1.2 (from mpm calibrate), outlier_limit: 10, warmup: 0,
//             gamma_lambda: 0.1, input_pole: 0, regressors: model_filtered,
//             settle_samples: auto}
//   transport:
//     kind: lcm                     # lcm | dds
//     lcm: {url: "udpm://239.255.76.67:7667?ttl=0", sample_channel: MPM_SAMPLE,
//           alarm_channel: MPM_ALARM, status_channel: MPM_STATUS}
//     dds: {domain: 0, config: cyclonedds-loopback.xml, sample_topic: mpm_sample,
//           alarm_topic: mpm_alarm, status_topic: mpm_status, sample_history: 64}
//   status_period: 1.0              # seconds
//   queue_capacity: 4096            # samples between receiver and monitor
//   log_interval: 60                # seconds between repeats of one kind of log line
//   max_sequence_jump: 1000000      # larger sequence jumps resynchronise (wire)
//   stale_after: auto               # seconds without a usable sample: not ready
//   checkpoint_path: /var/lib/mpm/mpmd.state  # relative to this file; absent = no checkpoint
//   checkpoint_interval: 60         # seconds between checkpoints (also written at SIGTERM)
//   diagnosis_window: 3000          # samples diagnosed (physics) at a raise; 0 = off
//   limits: {max_inputs: 100, max_outputs: 100, max_poly_length: 200,   # caps on the plant
//            max_delay_samples: 1000, max_yaml_bytes: 67108864}         # file (limits.hpp)
#pragma once

#include <cstdint>
#include <string>

#include "config/limits.hpp"
#include "core/granger_monitor.hpp"
#include "settings/transport_settings.hpp"

namespace mpm::config {

struct DaemonConfig {
  std::string source;          // the file it was read from
  std::string controller_id;   // samples of other controllers are ignored
  std::string plant_path;      // resolved against the config file's folder
  MonitorSettings monitor;
  bool input_pole_auto = false;  // input_pole: auto = the plant's dominant pole
  bool plain_lags = false;     // regressors: plain_lags (the paper's) or model_filtered
  int settle_samples = -1;     // samples skipped after the model starts; -1 = automatic
  transport::Settings transport;
  double status_period = 1.0;  // seconds between status messages
  int queue_capacity = 4096;   // samples buffered between receiver and monitor
  double log_interval = 60.0;  // seconds between repeats of one kind of log line
  std::int64_t max_sequence_jump = 1000000;  // largest plausible sequence gap or step back
  double stale_after = -1.0;   // seconds without a usable sample -> not ready; -1 = auto, 0 = never
  std::string checkpoint_path; // monitor state saved here and resumed at start; "" = none
  double checkpoint_interval = 60.0;  // seconds between checkpoints (and one at SIGTERM)
  int diagnosis_window = 3000; // recent samples diagnosed when an output is raised; 0 = none
  Limits limits;               // caps on the plant file (the config file itself: the defaults)
};

// `base_dir` resolves relative paths (plant, DDS config); "" = as given.
DaemonConfig parse_daemon_config(const std::string& yaml_text, const std::string& source_name,
                                 const std::string& base_dir);
// Also refuses a config or plant file that group or others may write, or that
// another non-root user owns (strict_modes.hpp).
DaemonConfig load_daemon_config(const std::string& path);

}  // namespace mpm::config
