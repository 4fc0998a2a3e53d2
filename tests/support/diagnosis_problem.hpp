// Synthetic one-output problems for the diagnosis library's tests: the
// fields every such test sets alike, in one place.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/diagnosis.hpp"

namespace mpm::test {

// Output "y" with the given inputs (du also serves as the absolute inputs),
// its residual y - G_M u, the nominal channels, and the disturbance model N
// with its variance; the monitor has flagged the output and located input 0.
inline diagnosis::Problem one_output_problem(std::vector<std::string> inputs, Eigen::MatrixXd du,
                                             Eigen::VectorXd residual, std::vector<std::optional<DiscreteTf>> nominal,
                                             DiscreteTf noise, double noise_variance) {
  diagnosis::Problem p;
  p.inputs = std::move(inputs);
  p.outputs = {"y"};
  p.u_abs = du;
  p.du = std::move(du);
  p.residual = std::move(residual);
  p.nominal = std::move(nominal);
  p.noise = {std::move(noise)};
  p.noise_variance = {noise_variance};
  p.monitor_flag = {true};
  p.monitor_located = {{0}};
  return p;
}

}  // namespace mpm::test
