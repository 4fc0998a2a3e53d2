// `mpm listen`: prints the monitors' alarms and status as JSON lines, the way
// an operator (or a test, or jq) watches them.

#include <chrono>
#include <cstdio>
#include <string>

#include "daemon/args.hpp"
#include "daemon/command.hpp"
#include "daemon/net_cli.hpp"
#include "transport/message_json.hpp"
#include "transport/transport.hpp"

namespace mpm {
namespace {

constexpr const char* kUsage =
    "usage: mpm listen (--transport lcm|dds | --config mpmd.yaml) [options]\n"
    "  Prints alarms, diagnoses and status messages, one JSON object per line, until interrupted.\n"
    "options:\n"
    "  --alarms-only         no status lines (and no diagnoses unless --diagnoses)\n"
    "  --diagnoses           print the diagnoses that follow raised alarms (default without --alarms-only)\n"
    "  --samples             print controller samples too\n"
    "  --controller ID       only messages of this controller\n"
    "  --count N             exit after N lines (exit 1 if the timeout comes first)\n"
    "  --timeout SECONDS     exit after this long (0 = never, the default)\n";

struct Filter {
  std::string controller;
  bool alarms_only = false;
  long count = 0;  // 0 = unlimited
  long printed = 0;

  bool wants(const std::string& controller_id) const { return controller.empty() || controller == controller_id; }
  void print(const std::string& line) {
    if (count > 0 && printed >= count) return;
    std::fputs(line.c_str(), stdout);
    std::fputc('\n', stdout);
    std::fflush(stdout);
    ++printed;
  }
  bool done() const { return count > 0 && printed >= count; }
};

int listen(transport::Transport& t, Filter& filter, bool samples, bool diagnoses, double timeout_s) {
  if (diagnoses || !filter.alarms_only) {
    t.subscribe_diagnoses([&](const msg::Diagnosis& d) {
      if (filter.wants(d.controller_id)) filter.print(msg::to_json(d));
    });
  }
  t.subscribe_alarms([&](const msg::Alarm& a) {
    if (filter.wants(a.controller_id)) filter.print(msg::to_json(a));
  });
  if (!filter.alarms_only) {
    t.subscribe_status([&](const msg::Status& s) {
      if (filter.wants(s.controller_id)) filter.print(msg::to_json(s));
    });
  }
  if (samples) {
    t.subscribe_samples([&](const msg::Sample& s) {
      if (filter.wants(s.controller_id)) filter.print(msg::to_json(s));
    });
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (!net_cli::g_stop && !filter.done()) {
    if (timeout_s > 0 && std::chrono::steady_clock::now() >= deadline) break;
    if (t.handle(std::chrono::milliseconds(100)) < 0 && !net_cli::g_stop) {
      std::fprintf(stderr, "mpm listen: the transport failed\n");
      return 1;
    }
  }
  return filter.count > 0 && !filter.done() ? 1 : 0;
}

int run(int argc, char** argv) {
  net_cli::NetOptions net;
  Filter filter;
  bool samples = false;
  bool diagnoses = false;
  double timeout_s = 0;
  const std::string usage = std::string(kUsage) + net_cli::kOptionsHelp;
  return run_command("mpm listen", usage.c_str(), argc, argv, net_cli::valued_options({"controller", "count", "timeout"}), {"alarms-only", "samples", "diagnoses"}, [&](const Args& args) {
    net = net_cli::read(args);
    filter.controller = args.get("controller").value_or("");
    filter.alarms_only = args.flag("alarms-only");
    filter.count = args.integer("count", 0);
    samples = args.flag("samples");
    diagnoses = args.flag("diagnoses");
    timeout_s = args.number("timeout", 0);
    if (filter.count < 0 || timeout_s < 0) throw UsageError("--count and --timeout must not be negative");
    std::string error;
    auto t = transport::create(net.transport, error);
    if (!t) {
      std::fprintf(stderr, "mpm listen: %s\n", error.c_str());
      return 1;
    }
    net_cli::stop_on_signals();
    return listen(*t, filter, samples, diagnoses, timeout_s);
  });
}

const bool registered =
    register_command({"listen", "print the monitors' alarms and status as JSON lines (LCM or DDS)", &run});

}  // namespace
}  // namespace mpm
