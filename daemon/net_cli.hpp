// Transport options shared by the `mpm` commands that speak LCM or DDS
// (cmd_*_net.cpp). Either --config names an mpmd.yaml (its transport,
// controller id and plant are used), or the options say it all; options
// override the file.
#pragma once

#include <atomic>
#include <csignal>
#include <optional>
#include <set>
#include <string>

#include "config/daemon_config.hpp"
#include "daemon/args.hpp"
#include "settings/transport_settings.hpp"

namespace mpm::net_cli {

constexpr const char* kOptionsHelp =
    "transport options:\n"
    "  --config FILE        take transport, controller id and plant from an mpmd.yaml\n"
    "  --transport lcm|dds  which transport (required without --config)\n"
    "  --lcm-url URL        LCM URL (default udpm://239.255.76.67:7667?ttl=0)\n"
    "  --dds-domain N       DDS domain id (default 0)\n"
    "  --dds-config FILE    Cyclone DDS XML configuration (default: $CYCLONEDDS_URI)\n"
    "  --sample-channel C, --alarm-channel C, --status-channel C   LCM channels / DDS topics\n";

// The options of a publisher (mpm replay, mpm simulate-live), for its usage.
constexpr const char* kPublisherHelp =
    "  --rate HZ              samples per second (default: 1 / the plant's sample_time)\n"
    "  --as-fast-as-possible  no pacing\n"
    "  --controller ID        controller id (default: the config's, else the plant's name)\n"
    "  --wait-readers SECONDS DDS: wait this long for a subscriber before publishing (default 10)\n";

// Set by SIGINT and SIGTERM once stop_on_signals() ran: the publishing and
// listening loops end at their next step.
inline std::atomic<bool> g_stop{false};
inline void stop_on_signals() {
  std::signal(SIGINT, [](int) { g_stop = true; });
  std::signal(SIGTERM, [](int) { g_stop = true; });
}

inline std::set<std::string> valued_options(std::set<std::string> more) {
  more.insert({"config", "transport", "lcm-url", "dds-domain", "dds-config", "sample-channel", "alarm-channel",
               "status-channel"});
  return more;
}

struct NetOptions {
  transport::Settings transport;
  std::optional<config::DaemonConfig> daemon;  // when --config was given
};

// Throws UsageError for a bad option, config::ConfigError for a bad file.
inline NetOptions read(const Args& args) {
  NetOptions o;
  if (auto path = args.get("config")) {
    o.daemon = config::load_daemon_config(*path);
    o.transport = o.daemon->transport;
  }
  // `--publish lcm|dds` is the same as --transport where a command takes it.
  const auto kind = args.get("transport") ? args.get("transport") : args.get("publish");
  if (!kind && !o.daemon) throw UsageError("--transport lcm|dds (or --config FILE) is required");
  if (kind && !transport::parse_kind(*kind, o.transport.kind)) {
    throw UsageError("--transport: expected lcm or dds, got '" + *kind + "'");
  }
  if (auto url = args.get("lcm-url")) o.transport.lcm.url = *url;
  o.transport.dds.domain = args.integer("dds-domain", o.transport.dds.domain);
  if (o.transport.dds.domain < 0 || o.transport.dds.domain > 230) throw UsageError("--dds-domain: expected 0..230");
  if (auto file = args.get("dds-config")) o.transport.dds.config = *file;
  if (auto c = args.get("sample-channel")) o.transport.lcm.sample_channel = o.transport.dds.sample_topic = *c;
  if (auto c = args.get("alarm-channel")) o.transport.lcm.alarm_channel = o.transport.dds.alarm_topic = *c;
  if (auto c = args.get("status-channel")) o.transport.lcm.status_channel = o.transport.dds.status_topic = *c;
  return o;
}

// Pacing of a publisher: --rate HZ or --as-fast-as-possible (rate 0); -1 when
// neither is given (the caller then paces at 1 / sample_time).
inline double read_rate(const Args& args) {
  if (args.flag("as-fast-as-possible") && args.get("rate"))
    throw UsageError("--rate and --as-fast-as-possible exclude each other");
  const double rate = args.flag("as-fast-as-possible") ? 0.0 : args.number("rate", -1);
  if (args.get("rate") && !(rate > 0)) throw UsageError("--rate: expected samples per second > 0");
  return rate;
}

}  // namespace mpm::net_cli
