// The closed loop of the paper's Fig. 2: DMC on the nominal model, a plant
// that may differ from it, coloured disturbances, setpoint changes.
//
// Streaming: ClosedLoop::step() returns one sample at a time (what a live
// publisher sends); batch: simulate() collects them into a Recording in the
// CSV layout of formats.md (t, inputs, outputs, r_<output>, extra signals),
// in absolute units = operating point + deviations.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "config/plant_loader.hpp"
#include "core/plant_model.hpp"
#include "sim/extra_input.hpp"
#include "sim/mpc.hpp"
#include "sim/noise.hpp"
#include "sim/plant_builder.hpp"
#include "sim/plant_sim.hpp"
#include "sim/setpoints.hpp"

namespace mpm::sim {

struct LoopConfig {
  PlantSpec plant;                      // the plant, relative to the model
  MpcSettings mpc;                      // deviation units for the limits
  std::vector<SetpointSpec> setpoints;  // one per output; empty = hold the operating point
  double default_noise_variance = 1.0;  // for outputs whose noise the plant file leaves out
  double noise_scale = 1.0;             // 0 = noiseless
  long warmup = 0;                      // samples run before the first one returned (t < 0)
};

// One sample at time k, absolute units. The spans point into the loop and
// stay valid until the next step().
struct LoopSample {
  long k = 0;
  double t = 0.0;
  std::span<const double> u, y, r, extra;  // extra: the recorded extra inputs
  std::span<const double> reference;        // the reference model's outputs; empty without one
};

class ClosedLoop {
 public:
  // Setup (allocates, runs the warm-up). Throws std::invalid_argument with a
  // message naming what does not fit.
  //
  // With a `reference` model (same input and output names), every sample also
  // carries what the sensors would have read had the plant been that model:
  // its linear channels, unedited, fed the loop's inputs, plus its own noise
  // filters driven by the same white innovations a_j. The measured outputs
  // minus these are the contribution of everything the reference leaves out,
  // on the recorded trajectory: known only in simulation, it is the
  // benchmark's oracle of how visible a mismatch is (scripts/
  // generalisation_bench.py). The reference does not act on the loop.
  ClosedLoop(const PlantModel& model, const LoopConfig& config, std::uint64_t seed,
             const PlantModel* reference = nullptr);

  // Real-time safe: measure y(k), choose u(k), apply it.
  const LoopSample& step() noexcept;

  // Recording columns: t, inputs, outputs, r_<output>, recorded extra inputs.
  const std::vector<std::string>& column_names() const noexcept { return columns_; }
  bool has_reference() const noexcept { return reference_.has_value(); }
  // Writes the sample's values in column order into row (column_names().size()).
  void fill_row(const LoopSample& s, double* row) const noexcept;

  const PlantModel& model() const noexcept { return model_; }
  const DmcController& controller() const noexcept { return mpc_; }

 private:
  PlantModel model_;
  OperatingPoint model_op_;
  OperatingPoint plant_op_;
  Plant plant_;
  DmcController mpc_;
  NoiseSource noise_;
  SetpointGenerator setpoints_;
  ExtraInputSource extra_source_;
  std::vector<double> extra_op_;
  std::vector<std::string> columns_;
  // Workspace (deviation units unless noted).
  std::vector<double> r_dev_, d_, y_plant_, y_ctrl_, u_ctrl_, u_plant_, extra_dev_;
  std::vector<double> u_abs_, y_abs_, r_abs_, extra_abs_;  // extra_abs_: recorded ones only
  std::vector<std::size_t> recorded_extra_;
  struct Reference {
    OperatingPoint op;
    Plant plant;
    NoiseSource noise;
    std::vector<double> d, y_dev, u_dev, y_abs;
  };
  std::optional<Reference> reference_;
  LoopSample sample_;
  long k_ = 0;
};

// Runs `samples` steps of the loop into a Recording (source = recording_name).
// With `reference` (the loop must have a reference model), also collects t
// and the reference's outputs, named as the model's, into it.
config::Recording simulate(ClosedLoop& loop, std::size_t samples, const std::string& recording_name = "simulation",
                           config::Recording* reference = nullptr);

}  // namespace mpm::sim
