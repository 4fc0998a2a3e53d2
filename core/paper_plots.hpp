// OVERVIEW: the data behind the paper's location plots (Chen, Xie & Su
// 2021, Figs. 3-5, 8-9, 11-13), for the HTML report; and the live
// detector's evidence at one sample, for its trace over a record.
//
// The paper judges a loop from batch least-squares fits of the residual d~:
//   * "R(u_i, nb), AR(d, 1..20)": the residual variance of d~ regressed on
//     its own lags 1..na and the lags 1..nb of one input u_i, for na = 1..20
//     and nb = 0, 1, 2 (Figs. 3-4): with no mismatch on u_i -> d~ the curves
//     of nb > 0 lie on the curve of nb = 0;
//   * the AR coefficients fitted beside the lags of u_i against those of
//     1 - N^-1 (Figs. 5, 9): on the channel that carries the mismatch they
//     match; on the others the AR part over-fits. gamma (the monitor's
//     index) measures the distance.
// The monitor computes the same quantities recursively with its own orders
// and model-filtered regressors; these plots use the paper's plain lags so
// that they read as the paper's figures. Batch, setup-style code: it
// allocates, and is not for a hot path. No I/O.
#pragma once

#include <cstddef>
#include <vector>

#include <Eigen/Dense>

#include "core/sequential_detector.hpp"

namespace mpm {

struct OrderSweep {
  int max_ar = 0;     // largest AR order swept (na = 1..max_ar)
  int max_input = 0;  // largest number of input lags (nb = 0..max_input)
  std::size_t used = 0;  // rows fitted: every regressor and the target finite
  // variance[i][nb][na - 1]: RSS / used of d~ on [1, d~ lags 1..na, u_i lags
  // 1..nb] (NaN when the fit is singular or too few rows).
  std::vector<std::vector<std::vector<double>>> variance;
  // ar[i]: the max_ar AR coefficients b_1..b_max_ar of the model [1, d~
  // lags 1..max_ar, u_i lags 1..max_input], in the sign of
  // d~(k) = sum b_j d~(k - j) + ... (the sign of 1 - N^-1's coefficients).
  std::vector<std::vector<double>> ar;
};

// The sweep for one output's residual d (NaN = missing) and the inputs u
// (samples x inputs, same rows). Rows whose lags reach a missing value are
// left out. Throws std::invalid_argument when max_ar < 1, max_input < 0 or
// the sizes differ.
OrderSweep order_sweep(const Eigen::VectorXd& d, const Eigen::MatrixXd& u, int max_ar = 20, int max_input = 2);

// The evidence of output j's statistic in a sequential detector at its last
// look: the largest T_W / h_W(k) over its windows (> 1: above a threshold,
// what raises the output). 0 before any look. Real-time safe.
double detector_evidence(const SequentialDetector& detector, std::size_t j) noexcept;

}  // namespace mpm
