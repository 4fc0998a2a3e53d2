// `mpm simulate`: runs a named closed-loop scenario (MPC on the nominal model,
// a plant that may differ from it) and writes the recording CSV of formats.md.
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "config/plant_loader.hpp"
#include "daemon/args.hpp"
#include "daemon/command.hpp"
#include "sim/closed_loop.hpp"
#include "sim/scenarios.hpp"

namespace mpm {
namespace {

constexpr const char* kUsage =
    "usage: mpm simulate --scenario NAME [--plant PLANT.yaml] [--samples N] [--seed S] --out RUN.csv\n"
    "       mpm simulate --list\n"
    "  Runs the closed loop of the scenario (DMC with IMC bias correction on the plant file's\n"
    "  model; the plant differs from it as the scenario says) and writes t, inputs, outputs and\n"
    "  r_<output> (plus any extra recorded signal) in absolute units.\n"
    "options:\n"
    "  --scenario NAME  which scenario (--list shows them)\n"
    "  --plant FILE     the nominal model (default: the scenario's file under config/, looked up\n"
    "                   in $MPM_CONFIG_DIR, the source tree and the install dir, else built in)\n"
    "  --samples N      samples to record (default 3000)\n"
    "  --seed S         random seed of noise and setpoint changes (default 1); same seed, same run\n"
    "  --out FILE       where to write the recording CSV\n"
    "  --list           list the scenarios and exit\n";

void list_scenarios() {
  for (const auto& s : sim::scenarios()) std::printf("  %-30s %s [%s]\n", s.name.c_str(), s.summary.c_str(), s.plant_file.c_str());
}

std::uint64_t parse_seed(const Args& args) {
  const auto text = args.get("seed");
  if (!text) return 1;
  if (text->empty() || text->find_first_not_of("0123456789") != std::string::npos)
    throw UsageError("--seed: expected a non-negative integer, got '" + *text + "'");
  errno = 0;
  const unsigned long long seed = std::strtoull(text->c_str(), nullptr, 10);
  if (errno == ERANGE) throw UsageError("--seed: too large for 64 bits");
  return seed;
}

std::size_t parse_samples(const Args& args) {
  const double n = args.number("samples", 3000);
  if (!(n >= 1 && n <= 1e8) || n != static_cast<double>(static_cast<long>(n)))
    throw UsageError("--samples: expected an integer from 1 to 100000000");
  return static_cast<std::size_t>(n);
}

int run_simulate(int argc, char** argv) {
  std::string out_path, scenario_name;
  std::size_t samples = 0;
  std::uint64_t seed = 0;
  std::optional<std::string> plant_path;
  try {
    const Args args(argc, argv, {"plant", "scenario", "samples", "seed", "out"}, {"list", "help"});
    if (args.flag("help")) {
      std::fputs(kUsage, stdout);
      return 0;
    }
    if (args.flag("list")) {
      list_scenarios();
      return 0;
    }
    scenario_name = args.required("scenario");
    out_path = args.required("out");
    samples = parse_samples(args);
    seed = parse_seed(args);
    plant_path = args.get("plant");
    if (!sim::find_scenario(scenario_name))
      throw UsageError("unknown scenario '" + scenario_name + "' (mpm simulate --list shows them)");
  } catch (const UsageError& e) {
    std::fprintf(stderr, "mpm simulate: %s\n%s", e.what(), kUsage);
    return 2;
  }
  try {
    const sim::Scenario& scenario = *sim::find_scenario(scenario_name);
    sim::ResolvedPlant plant = plant_path ? sim::ResolvedPlant{config::load_plant(*plant_path), *plant_path}
                                          : sim::default_plant(scenario);
    sim::ClosedLoop loop = [&] {
      try {
        return sim::ClosedLoop(plant.model, scenario.loop, seed);
      } catch (const std::invalid_argument& e) {
        throw std::runtime_error("scenario " + scenario.name + " does not fit the plant " + plant.source + ": " +
                                 e.what());
      }
    }();
    const config::Recording rec = sim::simulate(loop, samples, out_path);
    config::write_recording(out_path, rec);
    std::printf("wrote %s: %zu samples of %s (plant %s, seed %llu); input limits active at %zu samples\n",
                out_path.c_str(), samples, scenario.name.c_str(), plant.source.c_str(),
                static_cast<unsigned long long>(seed), loop.controller().constrained_samples());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mpm simulate: %s\n", e.what());
    return 1;
  }
}

const bool registered = register_command(
    {"simulate", "run a closed-loop scenario (MPC + mismatched plant) and write a recording", &run_simulate});

}  // namespace
}  // namespace mpm
