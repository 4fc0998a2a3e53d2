#include "config/daemon_config.hpp"

#include <cmath>
#include <filesystem>

#include "config/file_text.hpp"
#include "config/plant_loader.hpp"
#include "config/strict_modes.hpp"
#include "config/yaml_reader.hpp"

namespace mpm::config {
namespace {

using detail::Field;
using detail::YamlReader;

ConfigError yaml_error(const YAML::Exception& e, const std::string& source, const char* what) {
  const std::string where =
      e.mark.is_null() ? "" : std::to_string(e.mark.line + 1) + ":" + std::to_string(e.mark.column + 1) + ":";
  return ConfigError(source + ":" + where + " " + what + ": " + e.msg);
}

// exists() without its throwing overload: a path too long or otherwise
// unusable is "not there" (the caller names the key), never a
// filesystem_error without file or line.
bool file_exists(const std::string& path) {
  std::error_code error;
  return std::filesystem::exists(path, error) && !error;
}

std::string resolve(const std::string& path, const std::string& base_dir) {
  if (path.empty() || base_dir.empty() || std::filesystem::path(path).is_absolute()) return path;
  return (std::filesystem::path(base_dir) / path).lexically_normal().string();
}

// Optional scalars: read only when the key is present.
void read(const YamlReader& r, const Field& map, const char* key, int& out) {
  const Field f = r.child(map, key);
  if (f.present()) out = r.integer(f);
}
void read(const YamlReader& r, const Field& map, const char* key, double& out) {
  const Field f = r.child(map, key);
  if (f.present()) out = r.number(f);
}
void read(const YamlReader& r, const Field& map, const char* key, std::string& out) {
  const Field f = r.child(map, key);
  if (f.present()) out = r.name(f);
}

void read_monitor(const YamlReader& r, const Field& root, DaemonConfig& c) {
  const Field m = r.child(root, "monitor");
  if (!m.present() || m.node.IsNull()) return;
  r.check_keys(m, {"ar_order", "input_order", "forgetting", "false_alarm", "false_alarms_per_year", "sample_time",
                   "crossing_constant", "detector_thresholds", "outlier_limit", "warmup", "gamma_lambda", "input_pole", "regressors",
                   "settle_samples"});
  MonitorSettings& s = c.monitor;
  read(r, m, "ar_order", s.ar_order);
  read(r, m, "input_order", s.input_order);
  read(r, m, "forgetting", s.forgetting);
  read(r, m, "false_alarm", s.false_alarm);
  read(r, m, "false_alarms_per_year", s.detector.false_alarms_per_year);
  read(r, m, "sample_time", s.detector.sample_time);
  read(r, m, "crossing_constant", s.detector.crossing_constant);
  read(r, m, "outlier_limit", s.outlier_limit);
  if (const Field t = r.child(m, "detector_thresholds"); t.present()) s.detector.thresholds = r.numbers(t);
  read(r, m, "warmup", s.warmup);
  read(r, m, "gamma_lambda", s.gamma_lambda);
  const Field pole = r.child(m, "input_pole");
  if (pole.present() && pole.node.IsScalar() && pole.node.Scalar() == "auto") {
    c.input_pole_auto = true;
  } else {
    read(r, m, "input_pole", s.input_pole);
  }
  const Field regressors = r.child(m, "regressors");
  if (regressors.present()) {
    const std::string kind = r.name(regressors);
    if (kind != "model_filtered" && kind != "plain_lags")
      r.fail(regressors, "expected model_filtered or plain_lags, got \"" + kind + "\"");
    c.plain_lags = kind == "plain_lags";
  }
  const Field settle = r.child(m, "settle_samples");
  if (settle.present() && !(settle.node.IsScalar() && settle.node.Scalar() == "auto")) {
    c.settle_samples = r.integer(settle);
    if (c.settle_samples < 0) r.fail(settle, "expected \"auto\" or a number of samples >= 0");
  }
  // validate() names the field first ("forgetting must be in ..."): point at
  // that key when the file has it.
  if (const std::string problem = s.validate(); !problem.empty()) {
    for (const auto& kv : m.node) {
      const std::string key = kv.first.Scalar();
      if (problem.rfind(key + " ", 0) == 0) r.fail(r.child(m, key), problem);
    }
    r.fail(m, problem);
  }
}

void read_lcm(const YamlReader& r, const Field& t, transport::LcmSettings& lcm) {
  const Field f = r.child(t, "lcm");
  if (!f.present() || f.node.IsNull()) return;
  r.check_keys(f, {"url", "sample_channel", "alarm_channel", "status_channel", "diagnosis_channel"});
  read(r, f, "url", lcm.url);
  read(r, f, "sample_channel", lcm.sample_channel);
  read(r, f, "alarm_channel", lcm.alarm_channel);
  read(r, f, "status_channel", lcm.status_channel);
  read(r, f, "diagnosis_channel", lcm.diagnosis_channel);
}

void read_dds(const YamlReader& r, const Field& t, const std::string& base_dir, transport::DdsSettings& dds) {
  const Field f = r.child(t, "dds");
  if (!f.present() || f.node.IsNull()) return;
  r.check_keys(f, {"domain", "config", "sample_topic", "alarm_topic", "status_topic", "diagnosis_topic",
                   "sample_history"});
  read(r, f, "domain", dds.domain);
  if (dds.domain < 0 || dds.domain > 230) r.fail(r.child(f, "domain"), "expected a DDS domain id in 0..230");
  read(r, f, "config", dds.config);
  // A path to an XML file is relative to this file; inline XML and URIs are kept.
  if (!dds.config.empty() && dds.config.front() != '<' && dds.config.find("://") == std::string::npos) {
    dds.config = resolve(dds.config, base_dir);
    if (!file_exists(dds.config))
      r.fail(r.child(f, "config"), "no such Cyclone DDS configuration file: " + dds.config);
  }
  read(r, f, "sample_topic", dds.sample_topic);
  read(r, f, "alarm_topic", dds.alarm_topic);
  read(r, f, "status_topic", dds.status_topic);
  read(r, f, "diagnosis_topic", dds.diagnosis_topic);
  read(r, f, "sample_history", dds.sample_history);
  if (dds.sample_history < 1) r.fail(r.child(f, "sample_history"), "expected a history depth >= 1");
}

void read_transport(const YamlReader& r, const Field& root, const std::string& base_dir, DaemonConfig& c) {
  const Field t = r.child(root, "transport");
  if (!t.present() || t.node.IsNull()) return;
  r.check_keys(t, {"kind", "lcm", "dds"});
  const Field kind = r.child(t, "kind");
  if (kind.present() && !transport::parse_kind(r.name(kind), c.transport.kind))
    r.fail(kind, "expected lcm or dds, got \"" + r.name(kind) + "\"");
  read_lcm(r, t, c.transport.lcm);
  read_dds(r, t, base_dir, c.transport.dds);
}

void read_service(const YamlReader& r, const Field& root, DaemonConfig& c) {
  read(r, root, "status_period", c.status_period);
  if (c.status_period < 0.01 || c.status_period > 3600)
    r.fail(r.child(root, "status_period"), "expected seconds in 0.01..3600");
  read(r, root, "queue_capacity", c.queue_capacity);
  if (c.queue_capacity < 2 || c.queue_capacity > (1 << 20))
    r.fail(r.child(root, "queue_capacity"), "expected a number of samples in 2..1048576");
  read(r, root, "log_interval", c.log_interval);
  if (c.log_interval < 0) r.fail(r.child(root, "log_interval"), "expected seconds >= 0");
  if (const Field jump = r.child(root, "max_sequence_jump"); jump.present()) {
    const double n = r.number(jump);
    if (!(n >= 1 && n <= 1e15 && n == std::floor(n))) r.fail(jump, "expected a number of samples in 1..1e15");
    c.max_sequence_jump = static_cast<std::int64_t>(n);
  }
  const Field stale = r.child(root, "stale_after");
  if (stale.present() && !(stale.node.IsScalar() && stale.node.Scalar() == "auto")) {
    read(r, root, "stale_after", c.stale_after);
    if (!(c.stale_after >= 0)) r.fail(stale, "expected \"auto\" or seconds >= 0 (0 = never)");
  }
}

void read_checkpoint(const YamlReader& r, const Field& root, const std::string& base_dir, DaemonConfig& c) {
  read(r, root, "checkpoint_path", c.checkpoint_path);
  if (!c.checkpoint_path.empty()) c.checkpoint_path = resolve(c.checkpoint_path, base_dir);
  read(r, root, "checkpoint_interval", c.checkpoint_interval);
  if (!(c.checkpoint_interval >= 0.05 && c.checkpoint_interval <= 86400))
    r.fail(r.child(root, "checkpoint_interval"), "expected seconds in 0.05..86400");
  read(r, root, "diagnosis_window", c.diagnosis_window);
  if (c.diagnosis_window != 0 && (c.diagnosis_window < 200 || c.diagnosis_window > 1000000))
    r.fail(r.child(root, "diagnosis_window"), "expected 0 (off) or a number of samples in 200..1000000");
  read(r, root, "scan_interval", c.scan_interval);
  if (c.scan_interval != 0 && (c.scan_interval < 50 || c.scan_interval > 10000000))
    r.fail(r.child(root, "scan_interval"), "expected 0 (off) or a number of samples in 50..10000000");
}

// limits: {max_inputs: 200, ...}: the caps on the plant file (limits.hpp).
void read_limits(const YamlReader& r, const Field& root, DaemonConfig& c) {
  const Field f = r.child(root, "limits");
  if (!f.present() || f.node.IsNull()) return;
  if (!f.node.IsMap()) r.fail(f, "expected a map of caps (max_inputs: 200, ...)");
  for (const auto& kv : f.node) {
    const Field cap = r.child(f, kv.first.Scalar());
    if (const std::string problem = set_limit(c.limits, kv.first.Scalar(), r.number(cap)); !problem.empty())
      r.fail(cap, problem);
  }
}

}  // namespace

DaemonConfig parse_daemon_config(const std::string& yaml_text, const std::string& source_name,
                                 const std::string& base_dir) {
  const YamlReader r(source_name);
  YAML::Node document;
  try {
    document = YAML::Load(yaml_text);
  } catch (const YAML::Exception& e) {
    throw yaml_error(e, source_name, "invalid YAML");
  }
  const Field root = r.root(document);
  try {
    r.check_keys(root, {"controller_id", "plant", "monitor", "transport", "status_period", "queue_capacity",
                        "log_interval", "max_sequence_jump", "stale_after", "checkpoint_path",
                        "checkpoint_interval", "diagnosis_window", "scan_interval", "limits"});
    DaemonConfig c;
    c.source = source_name;
    c.controller_id = r.name(r.child(root, "controller_id"));
    const Field plant = r.child(root, "plant");
    c.plant_path = resolve(r.name(plant), base_dir);
    if (!file_exists(c.plant_path)) r.fail(plant, "no such plant file: " + c.plant_path);
    read_monitor(r, root, c);
    read_transport(r, root, base_dir, c);
    read_service(r, root, c);
    read_checkpoint(r, root, base_dir, c);
    read_limits(r, root, c);
    return c;
  } catch (const YAML::Exception& e) {
    throw yaml_error(e, source_name, "unexpected structure");
  }
}

DaemonConfig load_daemon_config(const std::string& path) {
  const std::string base_dir = std::filesystem::path(path).parent_path().string();
  check_strict_modes(path, "config");
  DaemonConfig c = parse_daemon_config(detail::read_file(path, Limits{}.max_yaml_bytes), path, base_dir);
  check_strict_modes(c.plant_path, "plant");
  return c;
}

}  // namespace mpm::config
