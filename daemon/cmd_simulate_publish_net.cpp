// `mpm simulate-live`: runs a closed-loop scenario live and publishes every
// sample on LCM or DDS, as the MPC of a real plant would: a demo source for
// mpmd that needs no recording.

#include <chrono>
#include <cstdio>
#include <random>
#include <string>
#include <thread>

#include "config/plant_loader.hpp"
#include "daemon/args.hpp"
#include "daemon/command.hpp"
#include "daemon/net_cli.hpp"
#include "sim/closed_loop.hpp"
#include "sim/scenarios.hpp"
#include "transport/transport.hpp"

namespace mpm {
namespace {

constexpr const char* kUsage =
    "usage: mpm simulate-live --scenario NAME --publish lcm|dds [options]\n"
    "  Runs the scenario's closed loop (mpm simulate --list) and publishes each sample as it\n"
    "  is made: inputs, outputs, setpoints and recorded extra signals.\n"
    "options:\n"
    "  --plant FILE           nominal model (default: the scenario's)\n"
    "  --samples N            samples to publish (default 0: until interrupted)\n"
    "  --seed S               random seed (default 1)\n";

std::int64_t unix_micros() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

struct Options {
  std::string scenario;
  std::optional<std::string> plant;
  std::string controller;
  long samples = 0;
  unsigned long seed = 1;
  double rate = -1;  // -1 = the plant's sample time, 0 = no pacing
  double wait_readers = 10;
};

int publish_loop(transport::Transport& t, sim::ClosedLoop& loop, const Options& o) {
  const PlantModel& plant = loop.model();
  const std::size_t ni = plant.n_inputs(), no = plant.n_outputs();
  // Extras: the recording's columns after t, inputs and outputs.
  const auto& columns = loop.column_names();
  msg::Sample s;
  s.controller_id = o.controller;
  s.session_id = static_cast<std::int64_t>(std::random_device{}() | 1u);
  s.extra_names.assign(columns.begin() + static_cast<std::ptrdiff_t>(1 + ni + no), columns.end());
  std::vector<double> row(columns.size());
  const double rate = o.rate < 0 ? 1.0 / plant.sample_time : o.rate;
  if (!t.wait_for_sample_readers(1, std::chrono::milliseconds(static_cast<long>(o.wait_readers * 1000)))) {
    std::fprintf(stderr, "mpm simulate-live: no subscriber after %g s; publishing anyway\n", o.wait_readers);
  }
  const auto start = std::chrono::steady_clock::now();
  long sent = 0;
  for (long k = 0; !net_cli::g_stop && (o.samples == 0 || k < o.samples); ++k) {
    if (rate > 0) std::this_thread::sleep_until(start + std::chrono::duration<double>(static_cast<double>(k) / rate));
    const sim::LoopSample& x = loop.step();
    loop.fill_row(x, row.data());
    s.seq = k + 1;
    s.utime = unix_micros();
    s.u.assign(row.begin() + 1, row.begin() + static_cast<std::ptrdiff_t>(1 + ni));
    s.y.assign(row.begin() + static_cast<std::ptrdiff_t>(1 + ni), row.begin() + static_cast<std::ptrdiff_t>(1 + ni + no));
    s.extra_values.assign(row.begin() + static_cast<std::ptrdiff_t>(1 + ni + no), row.end());
    if (t.publish(s)) ++sent;
  }
  t.flush(std::chrono::seconds(5));
  std::printf("published %ld samples of %s as controller '%s' on %s\n", sent, o.scenario.c_str(),
              o.controller.c_str(), t.describe().c_str());
  return 0;
}

int run(int argc, char** argv) {
  net_cli::NetOptions net;
  Options o;
  const std::string usage = std::string(kUsage) + net_cli::kPublisherHelp + net_cli::kOptionsHelp;
  return run_command("mpm simulate-live", usage.c_str(), argc, argv, net_cli::valued_options({"scenario", "publish", "plant", "samples", "seed", "rate", "controller",
                                             "wait-readers"}), {"as-fast-as-possible"}, [&](const Args& args) {
    net = net_cli::read(args);
    o.scenario = args.required("scenario");
    const sim::Scenario* found = sim::find_scenario(o.scenario);
    if (!found) throw UsageError("unknown scenario '" + o.scenario + "' (mpm simulate --list)");
    o.plant = args.get("plant");
    if (found->plant_file.empty() && !o.plant)
      throw UsageError("scenario " + o.scenario + " needs --plant FILE: it is tuned from the plant file given");
    o.controller = args.get("controller").value_or(net.daemon ? net.daemon->controller_id : "");
    o.samples = args.integer("samples", 0);
    o.seed = static_cast<unsigned long>(args.integer("seed", 1));
    o.rate = net_cli::read_rate(args);
    if (o.samples < 0) throw UsageError("--samples must not be negative");
    o.wait_readers = args.number("wait-readers", 10);
    const sim::Scenario& scenario = *found;
    const sim::ResolvedPlant plant =
        o.plant ? sim::ResolvedPlant{config::load_plant(*o.plant), *o.plant} : sim::default_plant(scenario);
    if (o.controller.empty()) o.controller = plant.model.name;
    sim::ClosedLoop loop(plant.model, sim::scenario_loop(scenario, plant.model), o.seed);
    std::string error;
    auto t = transport::create(net.transport, error);
    if (!t) throw std::runtime_error(error);
    t->advertise(transport::Transport::Topic::kSample);
    net_cli::stop_on_signals();
    return publish_loop(*t, loop, o);
  });
}

const bool registered = register_command(
    {"simulate-live", "run a closed-loop scenario live, publishing on LCM or DDS as the MPC would", &run});

}  // namespace
}  // namespace mpm
