// `mpm simulate`: runs a named closed-loop scenario (MPC on the nominal model,
// a plant that may differ from it) and writes the recording CSV of formats.md.
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "config/output_file.hpp"
#include "config/plant_loader.hpp"
#include "daemon/args.hpp"
#include "daemon/command.hpp"
#include "sim/closed_loop.hpp"
#include "sim/edit_spec.hpp"
#include "sim/scenarios.hpp"

namespace mpm {
namespace {

constexpr const char* kUsage =
    "usage: mpm simulate --scenario NAME [--plant PLANT.yaml] [--samples N] [--seed S] [--edit SPEC]...\n"
    "                    [--move-weight-scale X] [--reference-out REF.csv [--reference-plant MODEL.yaml]]\n"
    "                    --out RUN.csv\n"
    "       mpm simulate --list\n"
    "  Runs the closed loop of the scenario (DMC with IMC bias correction on the plant file's\n"
    "  model; the plant differs from it as the scenario says, plus any --edit) and writes t,\n"
    "  inputs, outputs and r_<output> (plus any extra recorded signal) in absolute units.\n"
    "options:\n"
    "  --scenario NAME  which scenario (--list shows them)\n"
    "  --plant FILE     the nominal model (default: the scenario's file under config/, looked up\n"
    "                   in $MPM_CONFIG_DIR, the source tree and the install dir, else built in);\n"
    "                   required by plant-nominal, which fits any plant: MPC horizons, weights and\n"
    "                   limits, setpoint steps and warm-up derived from the model, noise from its file\n"
    "  --samples N      samples to record (default 3000)\n"
    "  --seed S         random seed of noise and setpoint changes (default 1); same seed, same run\n"
    "  --edit SPEC      make the plant differ from the model (repeatable; names as in the plant file):\n"
    "                     OUTPUT.INPUT.KEY=VALUE  channel: gain (factor), pole (factor > 0 on every\n"
    "                       discrete pole), time_constant (factor > 0, gain kept), delay (extra\n"
    "                       samples, 0..10000), lag (pole of an extra unit-gain lag, [0, 1)),\n"
    "                       integrator (no value or =1; =0 removes the scenario's), soft_saturation\n"
    "                       (a >= 0: the channel acts on v / (1 + a |v|), v = the input's deviation)\n"
    "                     INPUT.KEY=VALUE   actuator: actuator_lag (pole, [0, 1)), lower (<= 0) and\n"
    "                       upper (>= 0) stops in deviation from the operating point, deadband (>= 0)\n"
    "                     OUTPUT.sensor_lag=VALUE   transmitter lag (pole, [0, 1))\n"
    "                   e.g. --edit y2.u1.gain=0.8 --edit u2.actuator_lag=0.45 --edit y1.sensor_lag=0.5\n"
    "                   Edits of one channel/input/output combine; a key the scenario already sets\n"
    "                   there is replaced, its other keys stay. Bad names, keys or values: exit 2.\n"
    "  --move-weight-scale X   multiply the controller's move weights by X > 0 (default 1):\n"
    "                   below 1 a tighter controller, whose inputs answer the noise more (more\n"
    "                   excitation), above 1 a calmer one\n"
    "  --out FILE       where to write the recording CSV\n"
    "  --reference-out FILE   also write t and the outputs the sensors would have read had the\n"
    "                   plant been the reference model (unedited, linear), fed the same inputs,\n"
    "                   with the same disturbance innovations through the reference's own noise\n"
    "                   filters. The recording's outputs minus these are what the model leaves out,\n"
    "                   on this run (a simulation-only oracle of a mismatch's size)\n"
    "  --reference-plant FILE  the reference model (default: the nominal model); same inputs and\n"
    "                   outputs as it, e.g. the plant file a diagnosis will be given\n"
    "  --list           list the scenarios and exit\n";

// The scenario's move weights (empty: all 1) times `scale`.
void scale_move_weights(sim::LoopConfig& loop, const PlantModel& model, double scale) {
  auto& weights = loop.mpc.move_weights;
  if (weights.empty()) weights.assign(model.inputs.size(), 1.0);
  for (double& w : weights) w *= scale;
}

std::string format_number(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", v);
  return text;
}

void list_scenarios() {
  for (const auto& s : sim::scenarios()) {
    const std::string plant = s.plant_file.empty() ? "--plant FILE" : s.plant_file;
    std::printf("  %-30s %s [%s]\n", s.name.c_str(), s.summary.c_str(), plant.c_str());
  }
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

int usage_error(const std::string& what) {
  std::fprintf(stderr, "mpm simulate: %s\n%s", what.c_str(), kUsage);
  return 2;
}

// The scenario's loop with the --edit specs applied to its plant; the names
// are the plant file's, so this runs once the plant is loaded.
sim::LoopConfig edited_loop(sim::LoopConfig loop, const PlantModel& model, const std::vector<std::string>& texts,
                            std::vector<sim::EditSpec>& specs) {
  for (const auto& text : texts) specs.push_back(sim::parse_edit(text, model.inputs, model.outputs));
  sim::apply_edits(specs, loop.plant);
  return loop;
}

int run_simulate(int argc, char** argv) {
  std::string out_path, scenario_name;
  std::vector<std::string> edit_texts;
  std::size_t samples = 0;
  std::uint64_t seed = 0;
  std::optional<std::string> plant_path;
  double move_weight_scale = 1.0;
  return run_command("mpm simulate", kUsage, argc, argv,
                     {"plant", "scenario", "samples", "seed", "out", "edit", "move-weight-scale", "reference-out",
                      "reference-plant"},
                     {"list"},
                     [&](const Args& args) {
    if (args.flag("list")) {
      list_scenarios();
      return 0;
    }
    scenario_name = args.required("scenario");
    out_path = args.required("out");
    samples = parse_samples(args);
    seed = parse_seed(args);
    plant_path = args.get("plant");
    edit_texts = args.all("edit");
    move_weight_scale = args.number("move-weight-scale", 1.0);
    if (!(move_weight_scale > 0.0 && move_weight_scale <= 1e6))
      throw UsageError("--move-weight-scale: expected a number in (0, 1e6]");
    const sim::Scenario* found = sim::find_scenario(scenario_name);
    if (!found) throw UsageError("unknown scenario '" + scenario_name + "' (mpm simulate --list shows them)");
    if (found->plant_file.empty() && !plant_path)
      throw UsageError("scenario " + scenario_name + " needs --plant FILE: it is tuned from the plant file given");
    const sim::Scenario& scenario = *found;
    sim::ResolvedPlant plant = plant_path ? sim::ResolvedPlant{config::load_plant(*plant_path), *plant_path}
                                          : sim::default_plant(scenario);
    const std::optional<std::string> reference_out = args.get("reference-out");
    const std::optional<std::string> reference_path = args.get("reference-plant");
    if (reference_path && !reference_out) throw UsageError("--reference-plant needs --reference-out");
    if (reference_out && *reference_out == out_path) throw UsageError("--reference-out: the same file as --out");
    std::optional<PlantModel> reference;
    if (reference_out) {
      reference = reference_path ? config::load_plant(*reference_path) : plant.model;
      if (reference->inputs != plant.model.inputs || reference->outputs != plant.model.outputs)
        throw UsageError("--reference-plant " + *reference_path + ": its inputs and outputs differ from the plant " +
                         plant.source + "'s");
    }
    std::vector<std::string> read_files{plant.source};
    if (reference_path) read_files.push_back(*reference_path);
    config::refuse_input_as_output(out_path, read_files);
    if (reference_out) config::refuse_input_as_output(*reference_out, read_files);
    std::vector<sim::EditSpec> edits;
    sim::LoopConfig loop_config = sim::scenario_loop(scenario, plant.model);
    try {
      loop_config = edited_loop(std::move(loop_config), plant.model, edit_texts, edits);
    } catch (const std::invalid_argument& e) {
      return usage_error(std::string("--edit ") + e.what());
    }
    scale_move_weights(loop_config, plant.model, move_weight_scale);
    std::string what = edits.empty() ? scenario.name : scenario.name + " with --edit " + sim::describe(edits);
    if (move_weight_scale != 1.0) what += " (move weights x " + format_number(move_weight_scale) + ")";
    sim::ClosedLoop loop = [&] {
      try {
        return sim::ClosedLoop(plant.model, loop_config, seed, reference ? &*reference : nullptr);
      } catch (const std::invalid_argument& e) {
        throw std::runtime_error("scenario " + what + " does not fit the plant " + plant.source + ": " + e.what());
      }
    }();
    config::Recording reference_rec;
    const config::Recording rec = sim::simulate(loop, samples, out_path, reference ? &reference_rec : nullptr);
    config::write_recording(out_path, rec);
    if (reference_out) config::write_recording(*reference_out, reference_rec);
    std::printf("wrote %s: %zu samples of %s (plant %s, seed %llu); input limits active at %zu samples\n",
                out_path.c_str(), samples, what.c_str(), plant.source.c_str(),
                static_cast<unsigned long long>(seed), loop.controller().constrained_samples());
    if (reference_out)
      std::printf("wrote %s: what the reference model %s would have measured on this run\n", reference_out->c_str(),
                  reference_path ? reference_path->c_str() : plant.source.c_str());
    config::write_stdout("");  // flushes; a failed write of the line above is an error
    return 0;
  });
}

const bool registered = register_command(
    {"simulate", "run a closed-loop scenario (MPC + mismatched plant) and write a recording", &run_simulate});

}  // namespace
}  // namespace mpm
