// Dynamic matrix control (DMC) on the nominal model with the IMC bias
// correction of the paper (Fig. 1): the controller predicts with G_M and
// shifts the whole prediction by today's model error y(k) - y_M(k), held over
// the horizon.
//
// OVERVIEW. The prediction vector holds the model outputs for k .. k+L-1 under
// the inputs applied so far; each sample it shifts by one and adds the step
// responses times the move just made (so no model state is simulated forward).
// The cost
//     sum_{i=1..P} sum_j Q_j (r_j - yhat_j(k+i))^2 + sum_{m<M} sum_l R_l du_l(k+m)^2
// is minimised over the next M inputs themselves (not their moves), which turns
// the input limits into plain bounds: a box QP. When the unconstrained optimum
// is inside the limits (the usual case) it is one precomputed matrix product.
#pragma once

#include <cstddef>
#include <vector>

#include <Eigen/Dense>

#include "core/plant_model.hpp"
#include "sim/box_qp.hpp"
#include "sim/step_response.hpp"

namespace mpm::sim {

struct MpcSettings {
  std::size_t prediction_horizon = 100;  // P, samples
  std::size_t control_horizon = 10;      // M, moves (<= P)
  std::vector<double> output_weights;    // Q_j on squared tracking error; empty = all 1
  std::vector<double> move_weights;      // R_l on squared moves; empty = all 1
  std::vector<double> input_lower;       // deviation units; empty = unbounded
  std::vector<double> input_upper;
  double settle_tolerance = 1e-10;       // step responses kept until settled to this (relative)
  std::size_t max_model_length = 50000;  // samples

  // Throws std::invalid_argument naming the setting that is wrong.
  void validate(std::size_t n_inputs, std::size_t n_outputs) const;
};

class DmcController {
 public:
  DmcController() = default;
  // Setup: step responses, dynamic matrix, gains. Throws std::invalid_argument.
  DmcController(const PlantModel& model, const MpcSettings& settings);

  std::size_t n_inputs() const noexcept { return n_in_; }
  std::size_t n_outputs() const noexcept { return n_out_; }
  std::size_t model_length() const noexcept { return steps_.length(); }

  // Real-time safe. y: measured outputs y(k); r: setpoints r(k) (held over
  // the horizon); u: written, the inputs u(k) to apply. Deviation units.
  void step(const double* y, const double* r, double* u) noexcept;
  // Back to rest: no moves made, prediction at zero.
  void reset() noexcept;

  // Samples at which the limits were active (the QP ran), and at which its
  // active-set method needed the gradient fallback.
  std::size_t constrained_samples() const noexcept { return constrained_; }
  std::size_t fallback_samples() const noexcept { return fallbacks_; }

 private:
  void build_gains(const MpcSettings& s);
  void shift_prediction(const double* du) noexcept;

  std::size_t n_in_ = 0, n_out_ = 0, horizon_ = 0, moves_ = 0;
  StepResponses steps_;
  Eigen::MatrixXd prediction_;     // n_out x L: model outputs at k .. k+L-1
  Eigen::MatrixXd gain_error_;     // (M n_in) x (P n_out): unconstrained v from the error
  Eigen::MatrixXd gain_input_;     // (M n_in) x n_in: ... from u(k-1)
  Eigen::MatrixXd hessian_;        // of the QP in v
  Eigen::VectorXd lower_, upper_;  // bounds on v (limits repeated M times)
  BoxQp qp_;
  // Workspace / state.
  Eigen::VectorXd u_prev_, du_, error_, v_, g_, bias_;
  std::size_t constrained_ = 0, fallbacks_ = 0;
};

}  // namespace mpm::sim
