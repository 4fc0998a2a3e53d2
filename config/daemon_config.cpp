#include "config/daemon_config.hpp"

#include <filesystem>
#include <variant>

#include "config/file_text.hpp"
#include "config/plant_loader.hpp"
#include "config/setting_text.hpp"
#include "config/strict_modes.hpp"
#include "config/yaml_reader.hpp"

namespace mpm::config {
namespace {

using detail::Field;
using detail::YamlReader;

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
void read(const YamlReader& r, const Field& map, const char* key, std::string& out) {
  const Field f = r.child(map, key);
  if (f.present()) out = r.name(f);
}

// One row's value, when its key is present: a list of numbers, or a scalar
// read as a flag's text would be (setting_text.hpp).
template <class S>
void read_row(const YamlReader& r, const Field& map, const FieldRow<S>& row, S& s) {
  const Field f = r.child(map, row.key);
  if (!f.present()) return;
  const auto ref = row.ref(s);
  if (auto* list = std::get_if<std::vector<double>*>(&ref)) {
    // [] states the default (an empty list: none) in the example file
    **list = f.node.IsSequence() && f.node.size() == 0 ? std::vector<double>{} : r.numbers(f);
    return;
  }
  if (!f.node.IsScalar()) r.fail_expected(f, "a single value");
  if (const std::string problem = set_from_text(row, s, f.node.Scalar()); !problem.empty()) r.fail(f, problem);
}

// The keys of a map the rows name (for check_keys), plus `more`.
template <class S>
std::vector<std::string> keys_of(const std::vector<FieldRow<S>>& rows, std::vector<std::string> more = {}) {
  for (const FieldRow<S>& row : rows) more.emplace_back(row.key);
  return more;
}

// Errors of settings read from `map`: each at its key when the file has it.
void fail_at_key(const YamlReader& r, const Field& map, const std::vector<FieldError>& errors) {
  if (errors.empty()) return;
  const Field at = r.child(map, errors.front().field);
  r.fail(at.present() ? at : map, errors.front().message);
}

void read_monitor(const YamlReader& r, const Field& root, DaemonConfig& c) {
  const Field m = r.child(root, "monitor");
  if (!m.present() || m.node.IsNull()) return;
  const auto& rows = ServiceSettings::monitor_fields();
  r.check_keys(m, keys_of(rows));
  for (const auto& row : rows) read_row<ServiceSettings>(r, m, row, c);
  fail_at_key(r, m, c.monitor.errors());  // what the settings break together (the detector's)
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

// The top-level keys of ServiceSettings and DaemonConfig.
void read_top_level(const YamlReader& r, const Field& root, const std::string& base_dir, DaemonConfig& c) {
  for (const auto& row : ServiceSettings::fields()) read_row<ServiceSettings>(r, root, row, c);
  for (const auto& row : DaemonConfig::fields()) read_row(r, root, row, c);
  if (!c.checkpoint_path.empty()) c.checkpoint_path = resolve(c.checkpoint_path, base_dir);
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

const std::vector<FieldRow<DaemonConfig>>& DaemonConfig::fields() {
  using S = DaemonConfig;
  static const std::vector<FieldRow<S>> rows = {
      {"status_period", [](S& s) { return &s.status_period; }, {.min = 0.01, .max = 3600}, "seconds between status messages"},
      {"queue_capacity", [](S& s) { return &s.queue_capacity; }, {.min = 2, .max = 1 << 20, .whole = true},
       "samples between the receiver thread and the monitor; a full queue drops, counts (`dropped`) and logs"},
      {"checkpoint_path", [](S& s) { return &s.checkpoint_path; }, {},
       "file of the monitor's state (relative to this file), written atomically every checkpoint_interval and at SIGTERM, resumed at start when the controller, settings and plant file's text are those it was written with; give each mpmd@ instance its own file"},
      {"checkpoint_interval", [](S& s) { return &s.checkpoint_interval; }, {.min = 0.05, .max = 86400},
       "seconds between checkpoints; one more at SIGTERM"},
  };
  return rows;
}

DaemonConfig parse_daemon_config(const std::string& yaml_text, const std::string& source_name,
                                 const std::string& base_dir) {
  const YamlReader r(source_name);
  const Field root = r.root(detail::load_document(yaml_text, source_name));
  return detail::read_checked(source_name, [&] {
    r.check_keys(root, keys_of(DaemonConfig::fields(), keys_of(ServiceSettings::fields(),
                                                                {"controller_id", "plant", "monitor", "transport", "limits"})));
    DaemonConfig c;
    c.source = source_name;
    c.controller_id = r.name(r.child(root, "controller_id"));
    const Field plant = r.child(root, "plant");
    c.plant_path = resolve(r.name(plant), base_dir);
    if (!file_exists(c.plant_path)) r.fail(plant, "no such plant file: " + c.plant_path);
    read_monitor(r, root, c);
    read_transport(r, root, base_dir, c);
    read_top_level(r, root, base_dir, c);
    read_limits(r, root, c);
    return c;
  });
}

DaemonConfig load_daemon_config(const std::string& path) {
  const std::string base_dir = std::filesystem::path(path).parent_path().string();
  check_strict_modes(path, "config");
  DaemonConfig c = parse_daemon_config(detail::read_file(path, Limits{}.max_yaml_bytes), path, base_dir);
  check_strict_modes(c.plant_path, "plant");
  return c;
}

}  // namespace mpm::config
