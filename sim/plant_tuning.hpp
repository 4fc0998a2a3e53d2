// A closed loop derived from the plant model alone, for the `plant-nominal`
// scenario: any plant file (any size, discrete or continuous channels, zero
// or absent channels, its own noise section) runs in closed loop without
// hand-written MPC tuning.
//
// OVERVIEW. Everything is scaled from two things the model gives: how long its
// step responses take to settle (horizon, setpoint periods, warm-up) and its
// steady-state gain matrix K (setpoint amplitudes, weights, limits). Inputs
// have no natural scale in a plant file, so the one choice made is that the
// setpoint steps need input moves of about one unit (RMS, geometric mean over
// the inputs); every output's setpoint and every weight follows from K.
#pragma once

#include <vector>

#include <Eigen/Dense>

#include "core/plant_model.hpp"
#include "sim/closed_loop.hpp"

namespace mpm::sim {

// The scales the tuning is built from (exposed for tests and docs).
struct PlantScales {
  long settling = 0;             // longest channel's 99 % settling, samples (uncapped, <= 20000)
  long horizon = 0;              // settling capped to 20 .. 300 samples
  Eigen::MatrixXd gain;          // n_out x n_in steady-state gains; integrators: slope x horizon
  Eigen::MatrixXd gain_inverse;  // n_in x n_out pseudo-inverse: the inputs that hold given outputs
  std::vector<double> amplitude; // per output: random setpoint steps are U(-a, a); 0 = unreachable output
  std::vector<double> move;      // per input: RMS move those steps need (geometric mean 1)
  std::vector<double> noise_std; // per output: stationary std of the disturbance d = N a
};

// Throws std::invalid_argument for a model without inputs or outputs.
PlantScales plant_scales(const PlantModel& model);

// The loop of `plant-nominal`: plant = model, MPC tuned from the scales,
// random setpoint steps on every output, the file's noise.
LoopConfig tuned_loop(const PlantModel& model);

}  // namespace mpm::sim
