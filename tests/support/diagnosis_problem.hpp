// Synthetic one-output problems for the diagnosis library's tests: the
// fields every such test sets alike, in one place.
#pragma once

#include <optional>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "core/diagnosis.hpp"
#include "core/diagnosis_signal.hpp"

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

// G(q) = 0.2 q^-1 / (1 - 0.8 q^-1): the first-order channel of the
// synthetic problems (unit gain, one sample of delay), and its response to u.
inline DiscreteTf first_order_model() { return DiscreteTf{{0.2}, {1.0, -0.8}, 1}; }
inline Eigen::VectorXd first_order_channel(const Eigen::VectorXd& u) {
  return diagnosis::simulate(first_order_model(), u);
}

// An input that steps to a level drawn uniformly in [-amplitude, amplitude]
// every 5 to 30 samples.
inline Eigen::VectorXd random_steps(std::mt19937& rng, Eigen::Index n, double amplitude) {
  std::uniform_int_distribution<int> hold(5, 30);
  std::uniform_real_distribution<double> level(-amplitude, amplitude);
  Eigen::VectorXd u(n);
  double v = 0.0;
  for (Eigen::Index k = 0, next = 0; k < n; ++k) {
    if (k == next) {
      v = level(rng);
      next = k + hold(rng);
    }
    u(k) = v;
  }
  return u;
}

}  // namespace mpm::test
