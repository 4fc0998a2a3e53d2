// State-space plants, as most MPC packages export them, turned into the
// per-channel transfer functions and per-output disturbance models the
// monitor uses (formats.md section 4.5). Pure math, used at load time only.
//
// OVERVIEW. A channel j <- i of x+ = A x + B u, y = C x + D u is
//   G_ji(z) = C_j (zI - A)^-1 B_i + D_ji
//           = [det(zI - A + B_i C_j) - det(zI - A)] / det(zI - A) + D_ji
// (the rank-one determinant identity), so each channel is two characteristic
// polynomials; roots that numerator and denominator share (states channel
// j <- i does not see: uncontrollable from u_i or unobservable in y_j) are
// cancelled, so a diagonal 4-state plant gives first-order channels, not
// fourth-order ones with cancelling zeros. A continuous model is first
// discretised exactly by a zero-order hold through the matrix exponential,
// [Ad Bd; 0 I] = exp([A B; 0 0] ts).
//
// The disturbance model: w (covariance W) enters through G, v (variances R)
// is added to each output. Output j's disturbance C_j (zI - A)^-1 G w + v_j
// has the innovations form N_j(z) = 1 + C_j (zI - A)^-1 K_j with the
// steady-state Kalman predictor gain K_j of that output alone: monic,
// minimum phase, stable where A's disturbance part is, with the innovation
// variance C_j P C_j' + R_j: exactly the d = N a of formats.md section 1.
#pragma once

#include <Eigen/Dense>
#include <optional>

#include "core/plant_model.hpp"

namespace mpm {

struct StateSpace {
  Eigen::MatrixXd A, B, C, D;  // n x n, n x m, p x n, p x m
  Eigen::MatrixXd G;           // n x nw disturbance input; 0 columns: no disturbance model
  Eigen::MatrixXd W;           // nw x nw covariance of w
  Eigen::VectorXd R;           // p measurement-noise variances
};

// Exact ZOH equivalent at ts of a continuous model (w held over the sample
// as u is). Throws std::invalid_argument for ts <= 0 or non-finite entries.
StateSpace discretize_zoh(const StateSpace& continuous, double ts);

// Channel j <- i of a discrete model, common roots cancelled; num all zero
// when u_i does not reach y_j.
DiscreteTf channel_tf(const StateSpace& discrete, std::size_t output, std::size_t input);

// Output j's innovations model (needs G with columns). Throws
// std::invalid_argument when the Riccati iteration does not settle or the
// innovation variance is not positive.
NoiseModel innovations_model(const StateSpace& discrete, std::size_t output);

}  // namespace mpm
