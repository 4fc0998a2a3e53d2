// mpmd.yaml: defaults, paths relative to the file, and errors that name the
// file, the line, the key and what was expected. Then mpmd itself: an
// invalid file at start is one clear error and a non-zero exit; the
// ready-made configurations are valid.
#include <gtest/gtest.h>

#include "child_process.hpp"
#include "config/daemon_config.hpp"
#include "config/plant_loader.hpp"

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
  std::string e = error_of(head + "monitor:\n  forgeting: 0.99\n");
  EXPECT_NE(e.find("mpmd.yaml:4:"), std::string::npos) << e;
  EXPECT_NE(e.find("monitor.forgeting"), std::string::npos) << e;
  EXPECT_NE(e.find("unknown key"), std::string::npos) << e;

  e = error_of(head + "monitor:\n  forgetting: 1.5\n");
  EXPECT_NE(e.find("mpmd.yaml:4:"), std::string::npos) << e;
  EXPECT_NE(e.find("monitor.forgetting"), std::string::npos) << e;
  EXPECT_NE(e.find("forgetting must be in (0.9, 1]"), std::string::npos) << e;

  e = error_of(head + "transport: {kind: zeromq}\n");
  EXPECT_NE(e.find("transport.kind"), std::string::npos) << e;
  EXPECT_NE(e.find("expected lcm or dds"), std::string::npos) << e;

  e = error_of(head + "monitor: {ar_order: ten}\n");
  EXPECT_NE(e.find("monitor.ar_order"), std::string::npos) << e;
  EXPECT_NE(e.find("expected an integer"), std::string::npos) << e;

  e = error_of("plant: wood-berry.yaml\n");
  EXPECT_NE(e.find("controller_id"), std::string::npos) << e;

  e = error_of("controller_id: wb\nplant: no-such-plant.yaml\n");
  EXPECT_NE(e.find("mpmd.yaml:2:"), std::string::npos) << e;
  EXPECT_NE(e.find("no such plant file"), std::string::npos) << e;

  e = error_of(head + "transport: {dds: {config: missing.xml}}\n");
  EXPECT_NE(e.find("transport.dds.config"), std::string::npos) << e;

  e = error_of(head + "transport: {dds: {domain: 300}}\n");
  EXPECT_NE(e.find("0..230"), std::string::npos) << e;

  e = error_of(head + "status_period: 0\n");
  EXPECT_NE(e.find("status_period"), std::string::npos) << e;

  e = error_of("controller_id: [unclosed\n");
  EXPECT_NE(e.find("mpmd.yaml:"), std::string::npos) << e;
  EXPECT_NE(e.find("invalid YAML"), std::string::npos) << e;
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
    const std::string what = e.what();
    EXPECT_NE(what.find("wood-berry.yaml:"), std::string::npos) << what;
    EXPECT_NE(what.find("delay"), std::string::npos) << what;
    EXPECT_NE(what.find("0..4"), std::string::npos) << what;
  }

  std::string e = error_of(head + "limits:\n  max_inputs: 0\n");
  EXPECT_NE(e.find("mpmd.yaml:4:"), std::string::npos) << e;
  EXPECT_NE(e.find("limits.max_inputs"), std::string::npos) << e;
  EXPECT_NE(e.find("1..10000"), std::string::npos) << e;
  e = error_of(head + "limits:\n  max_delay_samples: 2.5\n");
  EXPECT_NE(e.find("limits.max_delay_samples"), std::string::npos) << e;
  EXPECT_NE(e.find("whole number"), std::string::npos) << e;
  e = error_of(head + "limits:\n  max_pizza: 3\n");
  EXPECT_NE(e.find("mpmd.yaml:4:"), std::string::npos) << e;
  EXPECT_NE(e.find("no cap named max_pizza"), std::string::npos) << e;
  e = error_of(head + "limits: [1, 2]\n");
  EXPECT_NE(e.find("limits"), std::string::npos) << e;
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
