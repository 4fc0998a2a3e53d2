// `mpm replay`: publishes a recording sample by sample, as the controller
// would, on LCM or DDS: the controller's side for tests and demos.

#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <thread>

#include "config/plant_loader.hpp"
#include "daemon/args.hpp"
#include "daemon/command.hpp"
#include "daemon/net_cli.hpp"
#include "transport/transport.hpp"

namespace mpm {
namespace {

constexpr const char* kUsage =
    "usage: mpm replay --data RUN.csv (--plant PLANT.yaml | --config mpmd.yaml) [options]\n"
    "  Publishes the recording's samples (inputs, outputs, sim_<output> when every output has\n"
    "  one, other columns as named extra signals) as the controller would.\n"
    "options:\n"
    "  --session N            session id (default: random, i.e. a new publisher run)\n"
    "  --first-seq N          sequence number of the first sample (default 1)\n";

struct ReplayOptions {
  std::string data;
  std::string plant;
  std::string controller;
  double rate = 0;  // 0 = as fast as possible
  std::int64_t session = 0;
  std::int64_t first_seq = 1;
  double wait_readers = 10;
};

// The sample layout bound to the recording's columns.
struct Layout {
  config::BoundRecording bound;
  bool with_sim = false;
  std::vector<std::size_t> extra;  // setpoints and other signals
  std::vector<std::string> extra_names;
};

Layout layout_of(const PlantModel& plant, const config::Recording& rec) {
  Layout l{config::bind(plant, rec), true, {}, {}};
  for (const auto& s : l.bound.sim) l.with_sim = l.with_sim && s.has_value();
  for (const auto& r : l.bound.setpoints) {
    if (r) l.extra.push_back(*r);
  }
  l.extra.insert(l.extra.end(), l.bound.extra.begin(), l.bound.extra.end());
  for (const std::size_t c : l.extra) l.extra_names.push_back(rec.names[c]);
  return l;
}

void fill(const config::Recording& rec, const Layout& l, Eigen::Index k, msg::Sample& s) {
  s.u.resize(l.bound.inputs.size());
  for (std::size_t i = 0; i < l.bound.inputs.size(); ++i) s.u[i] = rec.data(k, static_cast<Eigen::Index>(l.bound.inputs[i]));
  s.y.resize(l.bound.outputs.size());
  for (std::size_t j = 0; j < l.bound.outputs.size(); ++j) s.y[j] = rec.data(k, static_cast<Eigen::Index>(l.bound.outputs[j]));
  s.sim_y.clear();
  if (l.with_sim) {
    for (const auto& c : l.bound.sim) s.sim_y.push_back(rec.data(k, static_cast<Eigen::Index>(*c)));
  }
  s.extra_values.resize(l.extra.size());
  for (std::size_t e = 0; e < l.extra.size(); ++e) s.extra_values[e] = rec.data(k, static_cast<Eigen::Index>(l.extra[e]));
}

std::int64_t unix_micros() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

int replay(transport::Transport& t, const PlantModel& plant, const config::Recording& rec, const ReplayOptions& o) {
  const Layout layout = layout_of(plant, rec);
  if (!t.wait_for_sample_readers(1, std::chrono::milliseconds(static_cast<long>(o.wait_readers * 1000)))) {
    std::fprintf(stderr, "mpm replay: no subscriber after %g s; publishing anyway\n", o.wait_readers);
  }
  msg::Sample s;
  s.controller_id = o.controller;
  s.session_id = o.session;
  s.extra_names = layout.extra_names;
  const auto start = std::chrono::steady_clock::now();
  std::size_t sent = 0, failed = 0;
  for (Eigen::Index k = 0; k < static_cast<Eigen::Index>(rec.samples()) && !net_cli::g_stop; ++k) {
    if (o.rate > 0) std::this_thread::sleep_until(start + std::chrono::duration<double>(static_cast<double>(k) / o.rate));
    s.seq = o.first_seq + k;
    s.utime = unix_micros();
    fill(rec, layout, k, s);
    if (t.publish(s)) {
      ++sent;
    } else {
      ++failed;
    }
  }
  t.flush(std::chrono::seconds(5));
  std::printf("published %zu samples of %s as controller '%s' on %s%s\n", sent, rec.source.c_str(),
              o.controller.c_str(), t.describe().c_str(), failed ? " (some failed)" : "");
  return failed ? 1 : 0;
}

std::int64_t random_session() {
  std::random_device rd;
  return static_cast<std::int64_t>((static_cast<std::uint64_t>(rd()) << 31) ^ rd()) | 1;
}

int run(int argc, char** argv) {
  net_cli::NetOptions net;
  ReplayOptions o;
  const std::string usage = std::string(kUsage) + net_cli::kPublisherHelp + net_cli::kOptionsHelp;
  return run_command("mpm replay", usage.c_str(), argc, argv, net_cli::valued_options({"data", "plant", "rate", "controller", "session", "first-seq",
                                             "wait-readers"}), {"as-fast-as-possible"}, [&](const Args& args) {
    net = net_cli::read(args);
    o.data = args.required("data");
    o.plant = args.get("plant").value_or(net.daemon ? net.daemon->plant_path : "");
    if (o.plant.empty()) throw UsageError("--plant (or --config) is required");
    o.controller = args.get("controller").value_or(net.daemon ? net.daemon->controller_id : "");
    o.rate = net_cli::read_rate(args);
    o.session = args.get("session") ? static_cast<std::int64_t>(args.number("session", 0)) : random_session();
    o.first_seq = static_cast<std::int64_t>(args.number("first-seq", 1));
    o.wait_readers = args.number("wait-readers", 10);
    const PlantModel plant = config::load_plant(o.plant);
    const config::Recording rec = config::load_recording(o.data);
    if (o.controller.empty()) o.controller = plant.name;
    if (o.rate < 0) o.rate = 1.0 / plant.sample_time;
    std::string error;
    auto t = transport::create(net.transport, error);
    if (!t) throw std::runtime_error(error);
    t->advertise(transport::Transport::Topic::kSample);
    net_cli::stop_on_signals();
    return replay(*t, plant, rec, o);
  });
}

const bool registered =
    register_command({"replay", "publish a recording on LCM or DDS as the controller would", &run});

}  // namespace
}  // namespace mpm
