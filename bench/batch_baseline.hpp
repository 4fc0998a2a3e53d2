// The naive way the monitor replaces: every sample, re-fit each regression the
// statistics need by batch least squares (Householder QR) over a sliding
// window of the last W samples. Per output j of an m-input loop that is
//   the full model [1, AR, u_1..u_m], m models without one input block,
//   the AR-only model (Sigma1), m pairwise models [1, AR, u_i] (whose AR
//   coefficients give gamma): 2m + 2 QR factorisations of W-row matrices.
#pragma once

#include <cstddef>
#include <vector>

#include <Eigen/Dense>

#include "bench/workload.hpp"

namespace mpm::bench {

class SlidingWindowBatch {
 public:
  // Needs w.samples > window + lags. Precomputes every regressor row.
  SlidingWindowBatch(const Workload& w, int ar_order, int input_order, std::size_t window);

  // Re-fits every model on the window ending at sample `k` (taken modulo the
  // valid range) and returns a checksum of the statistics (keeps the
  // optimiser honest; also lets a test compare with the monitor).
  double update(std::size_t k);

  std::size_t fits_per_update() const noexcept { return models_.size() * outputs_; }

 private:
  double rss_of(std::size_t output, std::size_t first_row, const std::vector<Eigen::Index>& columns);

  std::size_t outputs_;
  std::size_t inputs_;
  std::size_t na_;
  std::size_t nb_;
  std::size_t window_;
  std::size_t first_valid_;   // first sample with all lags available
  std::size_t valid_rows_;
  std::vector<Eigen::MatrixXd> rows_;  // per output: valid_rows x (p + 1), target last
  std::vector<std::vector<Eigen::Index>> models_;  // column sets, target column last
  Eigen::MatrixXd a_;                  // window x (columns) scratch
  Eigen::HouseholderQR<Eigen::MatrixXd> qr_;
  Eigen::VectorXd beta_;
};

}  // namespace mpm::bench
