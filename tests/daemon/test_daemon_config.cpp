// mpmd.yaml: defaults, paths relative to the file, and errors that name the
// file, the line, the key and what was expected. Then mpmd itself: an
// invalid file at start is one clear error and a non-zero exit; the
// ready-made configurations are valid.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "child_process.hpp"
#include "config/daemon_config.hpp"
#include "config/file_text.hpp"
#include "config/setting_text.hpp"
#include "config/settings_doc.hpp"
#include "config/plant_loader.hpp"
#include "support/mentions.hpp"

namespace mpm {
namespace {

using config::ConfigError;
using config::parse_daemon_config;

const std::string kPlant = MPM_SOURCE_DIR "/config/wood-berry.yaml";

std::string error_of(const std::string& yaml) {
  try {
    parse_daemon_config(yaml, "mpmd.yaml", MPM_SOURCE_DIR "/config");
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

// Config files, each with what its error must mention.
using ErrorCases = std::vector<std::pair<std::string, std::vector<std::string>>>;
void expect_errors(const ErrorCases& cases) {
  for (const auto& [yaml, fragments] : cases) EXPECT_TRUE(test::mentions(error_of(yaml), fragments)) << yaml;
}

TEST(DaemonConfig, MinimalFileTakesTheDefaults) {
  const auto c = parse_daemon_config("controller_id: wb\nplant: wood-berry.yaml\n", "mpmd.yaml", MPM_SOURCE_DIR "/config");
  EXPECT_EQ(c.controller_id, "wb");
  EXPECT_EQ(c.plant_path, kPlant) << "relative to the file's folder";
  const MonitorSettings defaults;
  EXPECT_EQ(c.monitor.ar_order, defaults.ar_order);
  EXPECT_EQ(c.monitor.forgetting, defaults.forgetting);
  EXPECT_EQ(c.monitor.false_alarm, defaults.false_alarm);
  EXPECT_EQ(c.settle_samples, -1);
  EXPECT_EQ(c.transport.kind, transport::Kind::kLcm);
  EXPECT_EQ(c.transport.lcm.url, "udpm://239.255.76.67:7667?ttl=0");
  EXPECT_EQ(c.transport.lcm.sample_channel, "MPM_SAMPLE");
  EXPECT_EQ(c.transport.lcm.alarm_channel, "MPM_ALARM");
  EXPECT_EQ(c.transport.lcm.status_channel, "MPM_STATUS");
  EXPECT_EQ(c.transport.dds.alarm_topic, "mpm_alarm");
  EXPECT_EQ(c.status_period, 1.0);
}

TEST(DaemonConfig, EverySettingIsRead) {
  const auto c = parse_daemon_config(
      "controller_id: c1\nplant: " + kPlant +
          "\nmonitor: {ar_order: 4, input_order: 12, forgetting: 0.99, false_alarm: 1e-4, false_alarms_per_year: 4,\n"
          "  sample_time: 2, outlier_limit: 7, detector_thresholds: [50, 51, 52, 53], warmup: 300, gamma_lambda: 0.2, input_pole: auto,\n"
          "  regressors: plain_lags, settle_samples: 50}\n"
          "transport:\n  kind: dds\n  lcm: {url: 'udpm://239.255.76.67:7700?ttl=1', sample_channel: S, alarm_channel: A,"
          " status_channel: T}\n"
          "  dds: {domain: 7, config: ../deploy/dds/cyclonedds-loopback.xml, sample_topic: s, alarm_topic: a,"
          " status_topic: t, sample_history: 128}\n"
          "status_period: 0.25\nqueue_capacity: 100\nlog_interval: 5\n",
      "mpmd.yaml", MPM_SOURCE_DIR "/config");
  EXPECT_EQ(c.monitor.ar_order, 4);
  EXPECT_EQ(c.monitor.input_order, 12);
  EXPECT_EQ(c.monitor.forgetting, 0.99);
  EXPECT_EQ(c.monitor.false_alarm, 1e-4);
  EXPECT_EQ(c.monitor.detector.false_alarms_per_year, 4.0);
  EXPECT_EQ(c.monitor.detector.sample_time, 2.0);
  EXPECT_EQ(c.monitor.outlier_limit, 7.0);
  EXPECT_EQ(c.monitor.detector.thresholds, (std::vector<double>{50, 51, 52, 53}));
  EXPECT_EQ(c.monitor.warmup, 300);
  EXPECT_EQ(c.monitor.gamma_lambda, 0.2);
  EXPECT_TRUE(c.input_pole_auto);
  EXPECT_TRUE(c.plain_lags);
  EXPECT_EQ(c.settle_samples, 50);
  EXPECT_EQ(c.transport.kind, transport::Kind::kDds);
  EXPECT_EQ(c.transport.lcm.url, "udpm://239.255.76.67:7700?ttl=1");
  EXPECT_EQ(c.transport.lcm.sample_channel, "S");
  EXPECT_EQ(c.transport.lcm.alarm_channel, "A");
  EXPECT_EQ(c.transport.lcm.status_channel, "T");
  EXPECT_EQ(c.transport.dds.domain, 7);
  EXPECT_EQ(c.transport.dds.config, MPM_SOURCE_DIR "/deploy/dds/cyclonedds-loopback.xml");
  EXPECT_EQ(c.transport.dds.sample_topic, "s");
  EXPECT_EQ(c.transport.dds.sample_history, 128);
  EXPECT_EQ(c.status_period, 0.25);
  EXPECT_EQ(c.queue_capacity, 100);
  EXPECT_EQ(c.log_interval, 5.0);
}

TEST(DaemonConfig, ErrorsNameFileLineKeyAndExpectation) {
  const std::string head = "controller_id: wb\nplant: wood-berry.yaml\n";
  expect_errors({
      {head + "monitor:\n  forgeting: 0.99\n", {"mpmd.yaml:4:", "monitor.forgeting", "unknown key"}},
      {head + "monitor:\n  forgetting: 1.5\n",
       {"mpmd.yaml:4:", "monitor.forgetting", "forgetting must be in (0.9, 1]"}},
      {head + "transport: {kind: zeromq}\n", {"transport.kind", "expected lcm or dds"}},
      {head + "monitor: {ar_order: ten}\n", {"monitor.ar_order", "expected an integer"}},
      {"plant: wood-berry.yaml\n", {"controller_id"}},
      {"controller_id: wb\nplant: no-such-plant.yaml\n", {"mpmd.yaml:2:", "no such plant file"}},
      {head + "transport: {dds: {config: missing.xml}}\n", {"transport.dds.config"}},
      {head + "transport: {dds: {domain: 300}}\n", {"0..230"}},
      {head + "status_period: 0\n", {"status_period"}},
      {"controller_id: [unclosed\n", {"mpmd.yaml:", "invalid YAML"}},
  });
}

// Validation returns {field, message}: a caller points at the key by its
// name, not by reading the text; every range is in one row.
TEST(DaemonConfig, ErrorsNameTheirField) {
  config::ServiceSettings s;
  EXPECT_TRUE(s.errors().empty());
  s.monitor.forgetting = 1.5;
  s.monitor.detector.crossing_constant = -1;
  s.stale_after = -3;
  s.diagnosis_window = 100;
  std::vector<std::string> fields;
  for (const FieldError& e : s.errors()) fields.push_back(e.field);
  EXPECT_EQ(fields, (std::vector<std::string>{"forgetting", "crossing_constant", "stale_after", "diagnosis_window"}));
  s.diagnosis_window = 0;  // its "off" value, outside its range
  s.stale_after = -1;      // "auto"
  EXPECT_EQ(s.errors().size(), 2u);
}

// A file's scalar and a flag's text are read by one function (setting_text.hpp):
// words, bools, whole numbers that must fit their type, ranges.
TEST(DaemonConfig, SettingTextIsCheckedBeforeItIsStored) {
  const auto row = [](const char* key) {
    for (const auto& r : config::ServiceSettings::monitor_fields())
      if (std::string(r.key) == key) return r;
    throw std::runtime_error(key);
  };
  config::ServiceSettings s;
  EXPECT_EQ(config::set_from_text(row("settle_samples"), s, "50"), "");
  EXPECT_EQ(s.settle_samples, 50);
  EXPECT_EQ(config::set_from_text(row("settle_samples"), s, "auto"), "");
  EXPECT_EQ(s.settle_samples, -1);
  EXPECT_EQ(config::set_from_text(row("input_pole"), s, "auto"), "");
  EXPECT_TRUE(s.input_pole_auto);
  EXPECT_EQ(config::set_from_text(row("regressors"), s, "plain_lags"), "");
  EXPECT_TRUE(s.plain_lags);
  EXPECT_NE(config::set_from_text(row("regressors"), s, "lags"), "");
  EXPECT_NE(config::set_from_text(row("warmup"), s, "1e30").find("expected an integer"), std::string::npos);
  EXPECT_NE(config::set_from_text(row("ar_order"), s, "4.5"), "");
  EXPECT_NE(config::set_from_text(row("forgetting"), s, "0.5").find("forgetting must be in (0.9, 1]"),
            std::string::npos);
  EXPECT_NE(config::set_from_text(row("forgetting"), s, "nan"), "");
  EXPECT_EQ(config::set_from_text(row("detector_thresholds"), s, "50,51.5"), "");
  EXPECT_EQ(s.monitor.detector.thresholds, (std::vector<double>{50, 51.5}));
  const config::ServiceSettings unchanged = s;
  EXPECT_NE(config::set_from_text(row("ar_order"), s, "300"), "");
  EXPECT_TRUE(s == unchanged) << "a refused value is not stored";
}

// One value of a number row other than its default, inside its range.
template <class S>
bool change(const FieldRow<S>& row, S& s) {
  const double now = number_of(row.get(s));
  if (std::isnan(now)) return false;
  const Range& r = row.range;
  double other = std::isfinite(r.max) ? r.max : now + 1;
  if (r.max_open || other == now) other = std::isfinite(r.min) ? r.min + (r.whole ? 1 : 0.001) : now - 1;
  if (other == now) other = now + (r.whole ? 1 : 0.001);
  EXPECT_TRUE(r.contains(other)) << row.key << " " << other;
  std::visit(
      [&](auto* p) {
        using T = std::remove_pointer_t<decltype(p)>;
        if constexpr (std::is_arithmetic_v<T>) *p = static_cast<T>(other);
      },
      row.ref(s));
  return true;
}

// A reload keeps the monitor only when every setting is the same
// (operator== = default) and the checkpoint's fingerprint (append_values)
// sees every row: a change of any one number setting shows in both.
TEST(DaemonConfig, EverySettingCountsForReloadAndFingerprint) {
  const config::ServiceSettings defaults;
  std::string base;
  config::append_values(config::ServiceSettings::monitor_fields(), defaults, base);
  config::append_values(config::ServiceSettings::fields(), defaults, base);
  int changed = 0;
  for (const auto* rows : {&config::ServiceSettings::monitor_fields(), &config::ServiceSettings::fields()}) {
    for (const auto& row : *rows) {
      config::ServiceSettings s = defaults;
      if (!change(row, s)) continue;
      ++changed;
      EXPECT_FALSE(s == defaults) << row.key;
      std::string f;
      config::append_values(config::ServiceSettings::monitor_fields(), s, f);
      config::append_values(config::ServiceSettings::fields(), s, f);
      EXPECT_NE(f, base) << row.key;
    }
  }
  EXPECT_GE(changed, 15);
}

// deploy/mpmd.yaml, the example config, lists every key of the tables with
// its default: read, it equals the defaults (its own controller, plant,
// transport and checkpoint path aside).
TEST(DaemonConfig, ExampleConfigListsEverySettingWithItsDefault) {
  const std::string text = config::detail::read_file(MPM_SOURCE_DIR "/deploy/mpmd.yaml", 1 << 20);
  const auto listed = [&](const std::string& indent, const char* key) {
    return text.find("\n" + indent + key + ":") != std::string::npos;
  };
  for (const auto& row : config::ServiceSettings::monitor_fields()) EXPECT_TRUE(listed("  ", row.key)) << row.key;
  for (const auto& row : config::ServiceSettings::fields()) EXPECT_TRUE(listed("", row.key)) << row.key;
  for (const auto& row : config::DaemonConfig::fields()) EXPECT_TRUE(listed("", row.key)) << row.key;
  for (const auto& row : config::Limits::fields()) EXPECT_TRUE(listed("  ", row.key)) << row.key;

  test::TempDir dir;  // as installed: the plant and the DDS configuration beside it
  dir.write("wood-berry.yaml", config::detail::read_file(kPlant, 1 << 20));
  dir.write("cyclonedds-loopback.xml", "<CycloneDDS/>");
  const auto c = parse_daemon_config(text, "mpmd.yaml", dir.path());
  config::ServiceSettings expected;
  expected.controller_id = c.controller_id;
  EXPECT_TRUE(static_cast<const config::ServiceSettings&>(c) == expected);
  const config::DaemonConfig defaults;
  EXPECT_EQ(c.status_period, defaults.status_period);
  EXPECT_EQ(c.queue_capacity, defaults.queue_capacity);
  EXPECT_EQ(c.checkpoint_interval, defaults.checkpoint_interval);
  EXPECT_TRUE(c.limits == defaults.limits);
}

// deploy/README.md's table of settings is the tables' own, as
// `mpmd --settings-table` prints it (regenerate it with that).
TEST(DaemonConfig, DocsTableIsGeneratedFromTheRows) {
  const std::string text = config::detail::read_file(MPM_SOURCE_DIR "/deploy/README.md", 1 << 20);
  const std::string begin = "<!-- settings table: mpmd --settings-table -->\n";
  const auto from = text.find(begin);
  const auto to = text.find("<!-- end of settings table -->");
  ASSERT_NE(from, std::string::npos);
  ASSERT_NE(to, std::string::npos);
  EXPECT_EQ(text.substr(from + begin.size(), to - from - begin.size()), config::settings_table_markdown());
}

// The loaders' caps (config/limits.hpp) from a `limits:` section: a plant
// beyond a default cap loads once the cap is raised; a lowered cap refuses
// it, located in the plant file; a bad cap is located in the config file.
TEST(DaemonConfig, LimitsSectionSetsTheLoadersCaps) {
  const std::string head = "controller_id: wb\nplant: wood-berry.yaml\n";
  const auto c = parse_daemon_config(head + "limits:\n  max_inputs: 300\n  max_delay_samples: 5000\n"
                                            "  max_csv_columns: 20\n  max_yaml_bytes: 1e6\n",
                                     "mpmd.yaml", MPM_SOURCE_DIR "/config");
  EXPECT_EQ(c.limits.max_inputs, 300u);
  EXPECT_EQ(c.limits.max_delay_samples, 5000);
  EXPECT_EQ(c.limits.max_csv_columns, 20u);
  EXPECT_EQ(c.limits.max_yaml_bytes, 1000000u);
  EXPECT_EQ(c.limits.max_outputs, config::Limits{}.max_outputs) << "caps not given keep their defaults";

  // G21's delay is 8 samples: a cap of 4 refuses the plant, naming the file and key.
  const auto low = parse_daemon_config(head + "limits: {max_delay_samples: 4}\n", "mpmd.yaml", MPM_SOURCE_DIR "/config");
  try {
    config::load_plant(low.plant_path, low.limits);
    ADD_FAILURE() << "a delay of 8 passed a cap of 4";
  } catch (const ConfigError& e) {
    EXPECT_TRUE(test::mentions(e.what(), {"wood-berry.yaml:", "delay", "0..4"}));
  }

  expect_errors({
      {head + "limits:\n  max_inputs: 0\n", {"mpmd.yaml:4:", "limits.max_inputs", "1..10000"}},
      {head + "limits:\n  max_delay_samples: 2.5\n", {"limits.max_delay_samples", "whole number"}},
      {head + "limits:\n  max_pizza: 3\n", {"mpmd.yaml:4:", "no cap named max_pizza"}},
      {head + "limits: [1, 2]\n", {"limits"}},
  });
}

TEST(Mpmd, InvalidConfigAtStartIsOneClearErrorAndExitOne) {
  test::TempDir dir;
  dir.write("mpmd.yaml", "controller_id: wb\nplant: " + kPlant + "\nmonitor: {false_alarm: 2}\n");
  test::ChildProcess mpmd({MPM_BINARY_DIR "/daemon/mpmd/mpmd", "--config", dir.file("mpmd.yaml")},
                          dir.file("out"), dir.file("err"));
  EXPECT_EQ(mpmd.wait_exit(std::chrono::seconds(30)), 1);
  const std::string err = mpmd.stderr_text();
  EXPECT_EQ(test::count_lines(err, ""), 1) << err;
  EXPECT_NE(err.find("<3>"), std::string::npos) << "journald error priority: " << err;
  EXPECT_NE(err.find(dir.file("mpmd.yaml") + ":3:"), std::string::npos) << err;
  EXPECT_NE(err.find("false_alarm"), std::string::npos) << err;
}

TEST(Mpmd, MissingFileAndBadArgumentsFail) {
  test::TempDir dir;
  test::ChildProcess missing({MPM_BINARY_DIR "/daemon/mpmd/mpmd", "--config", dir.file("nope.yaml")},
                             dir.file("out"), dir.file("err"));
  EXPECT_EQ(missing.wait_exit(std::chrono::seconds(30)), 1);
  EXPECT_NE(missing.stderr_text().find("nope.yaml"), std::string::npos) << missing.stderr_text();
  test::ChildProcess no_args({MPM_BINARY_DIR "/daemon/mpmd/mpmd"}, dir.file("out2"), dir.file("err2"));
  EXPECT_EQ(no_args.wait_exit(std::chrono::seconds(30)), 2);
}

TEST(Mpmd, ReadyMadeConfigurationsAreValid) {
  for (const char* name : {"mpmd-wood-berry-lcm.yaml", "mpmd-wood-berry-dds.yaml"}) {
    test::TempDir dir;
    test::ChildProcess check({MPM_BINARY_DIR "/daemon/mpmd/mpmd", "--config",
                              std::string(MPM_SOURCE_DIR "/config/") + name, "--check"},
                             dir.file("out"), dir.file("err"));
    EXPECT_EQ(check.wait_exit(std::chrono::seconds(30)), 0) << name << ": " << check.stderr_text();
    EXPECT_NE(check.stdout_text().find("valid"), std::string::npos);
  }
  const auto dds = config::load_daemon_config(MPM_SOURCE_DIR "/config/mpmd-wood-berry-dds.yaml");
  EXPECT_EQ(dds.transport.kind, transport::Kind::kDds);
  EXPECT_EQ(dds.transport.dds.config, MPM_SOURCE_DIR "/deploy/dds/cyclonedds-loopback.xml");
  const auto lcm = config::load_daemon_config(MPM_SOURCE_DIR "/config/mpmd-wood-berry-lcm.yaml");
  EXPECT_EQ(lcm.transport.kind, transport::Kind::kLcm);
  EXPECT_EQ(lcm.controller_id, dds.controller_id);
}

}  // namespace
}  // namespace mpm
