#include "sim/step_response.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "core/transfer_function.hpp"

namespace mpm::sim {
namespace {

// Index from which a stable response stays within tol * scale of its gain.
std::size_t settled_at_gain(const Eigen::RowVectorXd& s, double gain, double tolerance) {
  const double scale = std::max(std::abs(gain), s.cwiseAbs().maxCoeff());
  for (Eigen::Index n = s.size() - 1; n >= 0; --n)
    if (std::abs(s(n) - gain) > tolerance * scale) return static_cast<std::size_t>(n) + 1;
  return 0;
}

// Index from which the second difference stays within tol * max|s|: from
// there on the response is a straight line (an integrating channel).
std::size_t settled_to_ramp(const Eigen::RowVectorXd& s, double tolerance) {
  const double scale = s.cwiseAbs().maxCoeff();
  for (Eigen::Index n = s.size() - 1; n >= 2; --n) {
    const double second = s(n) - 2.0 * s(n - 1) + s(n - 2);
    if (std::abs(second) > tolerance * scale) return static_cast<std::size_t>(n) + 1;
  }
  return 0;
}

}  // namespace

StepResponses::StepResponses(const PlantModel& model, std::size_t min_length, double tolerance,
                             std::size_t max_length)
    : n_inputs_(model.n_inputs()), ramps_(model.n_outputs(), false) {
  const std::size_t rows = model.n_outputs() * n_inputs_;
  Eigen::MatrixXd full =
      Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(rows), static_cast<Eigen::Index>(max_length));
  std::vector<bool> row_ramps(rows, false);
  std::size_t needed = std::max<std::size_t>(min_length, 3);
  for (const auto& c : model.channels) {
    if (c.tf.is_zero()) continue;
    const std::size_t row = c.output * n_inputs_ + c.input;
    const auto r = static_cast<Eigen::Index>(row);
    DiscreteFilter f(c.tf);
    for (std::size_t n = 0; n < max_length; ++n) full(r, static_cast<Eigen::Index>(n)) = f.step(1.0);
    const bool stable = c.tf.is_stable();
    row_ramps[row] = !stable;
    const std::size_t settled = stable ? settled_at_gain(full.row(r), c.tf.dc_gain(), tolerance)
                                       : settled_to_ramp(full.row(r), tolerance);
    // Settling in the last tenth of the window means it may never settle.
    if (settled + max_length / 10 > max_length)
      throw std::invalid_argument("model channel " + model.outputs[c.output] + " <- " + model.inputs[c.input] +
                                  ": the step response has not settled after " + std::to_string(max_length) +
                                  " samples (unstable, or too slow for the controller)");
    needed = std::max(needed, settled + 2);
  }
  s_ = full.leftCols(static_cast<Eigen::Index>(needed));
  slope_ = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(rows));
  for (std::size_t row = 0; row < rows; ++row) {
    if (!row_ramps[row]) continue;
    const auto r = static_cast<Eigen::Index>(row);
    slope_(r) = s_(r, s_.cols() - 1) - s_(r, s_.cols() - 2);
    ramps_[row / n_inputs_] = true;
  }
}

double StepResponses::at(std::size_t j, std::size_t l, std::size_t n) const noexcept {
  const auto row = static_cast<Eigen::Index>(j * n_inputs_ + l);
  const auto last = s_.cols() - 1;
  const auto col = static_cast<Eigen::Index>(n);
  if (col <= last) return s_(row, col);
  return s_(row, last) + static_cast<double>(col - last) * slope_(row);
}

}  // namespace mpm::sim
