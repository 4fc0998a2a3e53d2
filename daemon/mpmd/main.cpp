// mpmd: watches one Model Predictive Controller for model-plant mismatch.
//
//   mpmd --config /etc/mpm/mpmd.yaml
//
// Subscribes to the controller's samples (LCM or DDS), updates the Granger
// monitor every sample, publishes alarms when a channel's state changes and a
// status periodically. Under systemd (Type=notify): READY=1 once serving,
// WATCHDOG=1 while healthy, SIGHUP reloads the configuration (an invalid one
// is logged and the running one kept), SIGTERM stops cleanly. Logs go to
// stderr with syslog priority prefixes for journald.
#include <signal.h>

#include <atomic>
#include <cstdio>
#include <cstring>
#include <string>

#include "config/settings_doc.hpp"
#include "daemon/args.hpp"
#include "daemon/mpmd/log.hpp"
#include "daemon/mpmd/notifier.hpp"
#include "daemon/mpmd/receiver.hpp"
#include "daemon/mpmd/sample_queue.hpp"
#include "daemon/mpmd/service_loop.hpp"
#include "daemon/mpmd/setup.hpp"
#include "transport/transport.hpp"

namespace {

static_assert(std::atomic<bool>::is_always_lock_free, "signal handlers need lock-free flags");
std::atomic<bool> g_stop{false};
std::atomic<bool> g_reload{false};

extern "C" void on_stop_signal(int) { g_stop = true; }
extern "C" void on_reload_signal(int) { g_reload = true; }

// Handlers only set flags; no SA_RESTART, so the main loop's poll() returns.
void install_signal_handlers() {
  struct sigaction stop {};
  stop.sa_handler = on_stop_signal;
  sigemptyset(&stop.sa_mask);
  sigaction(SIGTERM, &stop, nullptr);
  sigaction(SIGINT, &stop, nullptr);
  struct sigaction reload {};
  reload.sa_handler = on_reload_signal;
  sigemptyset(&reload.sa_mask);
  sigaction(SIGHUP, &reload, nullptr);
  signal(SIGPIPE, SIG_IGN);
}

constexpr const char* kUsage =
    "usage: mpmd --config FILE\n"
    "  Watches one controller for model-plant mismatch (see README: mpmd).\n"
    "  --config FILE   service configuration (YAML)\n"
    "  --check         load and validate the configuration, then exit\n"
    "  --settings-table  print every setting (key, default, allowed values, meaning) as Markdown\n"
    "  --version       print the version and exit\n";

struct Options {
  std::string config_path;
  bool check_only = false;
};

constexpr int kRun = -1;

// kRun, or the exit code (--help, --version, --settings-table: 0; a usage
// error: 2, as every mpm command).
int parse_options(int argc, char** argv, Options& options) {
  return mpm::run_command("mpmd", kUsage, argc, argv, {"config"}, {"check", "settings-table"},
                          [&](const mpm::Args& args) {
                            if (args.flag("settings-table")) {
                              std::fputs(mpm::config::settings_table_markdown().c_str(), stdout);
                              return mpm::kExitOk;
                            }
                            options.config_path = args.required("config");
                            options.check_only = args.flag("check");
                            return kRun;
                          });
}

}  // namespace

int main(int argc, char** argv) {
  using namespace mpm;
  Options options;
  if (const int rc = parse_options(argc, argv, options); rc != kRun) return rc;
  install_signal_handlers();

  // 1. Configuration: one clear error and a non-zero exit when invalid.
  std::string error;
  std::optional<LoadedConfig> loaded = load_config(options.config_path, error);
  if (!loaded) {
    log::write(log::Level::kError, "%s", error.c_str());
    return 1;
  }

  // 2. The monitor (its alarms go out through the transport made next).
  std::unique_ptr<transport::Transport> transport;
  std::unique_ptr<MonitorService> service = make_service(*loaded, publish_to(transport), error);
  if (!service) {
    log::write(log::Level::kError, "%s", error.c_str());
    return 1;
  }
  if (options.check_only) {
    std::printf("%s: valid (controller '%s', plant %s)\n", options.config_path.c_str(),
                loaded->config.controller_id.c_str(), loaded->config.plant_path.c_str());
    return 0;
  }
  // The state of the previous run, when it fits this plant and these settings.
  const bool resumed = resume_from_checkpoint(service, *loaded, error);
  if (!service) {
    log::write(log::Level::kError, "%s", error.c_str());
    return 1;
  }

  // 3. Transport, the bounded queue and the receiver thread.
  // Every received sample is checked against the plant's dimensions before
  // the transport copies it (transport/lcm_wire.hpp).
  transport::Settings transport_settings = loaded->config.transport;
  transport_settings.sample_limits.n_u = static_cast<std::uint32_t>(loaded->plant.n_inputs());
  transport_settings.sample_limits.n_y = static_cast<std::uint32_t>(loaded->plant.n_outputs());
  transport = transport::create(transport_settings, error);
  if (!transport) {
    log::write(log::Level::kError, "%s", error.c_str());
    return 1;
  }
  transport->advertise(transport::Transport::Topic::kAlarm);
  transport->advertise(transport::Transport::Topic::kStatus);
  transport->advertise(transport::Transport::Topic::kDiagnosis);
  if (resumed) service->republish_raised("the service restarted and resumed from its checkpoint");
  SampleQueue queue(static_cast<std::size_t>(loaded->config.queue_capacity));
  Receiver receiver(*transport, queue);
  if (!receiver.start(error)) {
    log::write(log::Level::kError, "%s", error.c_str());
    return 1;
  }

  // 4. Serving: tell systemd.
  const std::string serving = "watching controller '" + loaded->config.controller_id + "' on " + transport->describe();
  Notifier notifier;
  notifier.ready(serving);
  log::write(log::Level::kNotice, "%s (plant %s, %zu inputs, %zu outputs, settle %d samples)", serving.c_str(),
             loaded->config.plant_path.c_str(), loaded->plant.n_inputs(), loaded->plant.n_outputs(),
             service->settle_samples());

  // 5. Until SIGTERM / SIGINT; SIGHUP reloads.
  ServiceLoop loop(options.config_path, std::move(*loaded), std::move(service), queue, receiver, *transport,
                   notifier);
  const int rc = loop.run(g_stop, g_reload);

  // 6. Tear down in reverse.
  notifier.stopping();
  receiver.stop();
  log::write(log::Level::kNotice, "stopped");
  return rc;
}
