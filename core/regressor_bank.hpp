// The regressors of the Granger monitor's models, one sample at a time:
// per output j the last na residuals d~_j(k-1..k-na), newest first, and per
// channel (j, i) nb regressors of input i, each with at least one sample of
// delay: plain lags u_i(k-1..k-nb) (the default), lags of G_ji u_i through
// the nominal channel model (model-filtered regressors), or an orthonormal
// Laguerre basis with pole a (input_pole > 0) applied to either.
//
// The input regressors see u - u_ref, u_ref the input level at (re)start,
// so the basis and the model filters start at rest there. After a start or
// a gap the bank needs lags_needed() samples before its rows are valid: na
// residuals, nb input samples, and the memory of the filters and of the
// Laguerre states (zeroed at the gap) decayed to 1 %; at the first start
// of a residual that needs no settling only the lags (start_settled()).
#pragma once

#include <algorithm>
#include <cstddef>
#include <optional>
#include <vector>

#include <Eigen/Dense>

#include "core/transfer_function.hpp"

namespace mpm {

class RegressorBank {
 public:
  RegressorBank() = default;
  // Allocates everything. `channel_models`: empty or n_outputs * n_inputs
  // entries (output major), nullopt or a zero channel for plain lags (an
  // unstable one also gets plain lags: its filter would drift). Only the
  // channels of outputs [first_output, end_output) are stepped.
  RegressorBank(std::size_t n_inputs, std::size_t n_outputs, std::size_t na, std::size_t nb, double input_pole,
                const std::vector<std::optional<DiscreteTf>>& channel_models, std::size_t first_output,
                std::size_t end_output);

  // Samples before the rows are used: after a gap, the lags and then until
  // the memory the filters lost has decayed; at the first start the same,
  // or only the lags after start_settled().
  int lags_needed() const noexcept { return lags_wait_; }
  // Enough valid consecutive samples for the rows to be valid.
  bool filled() const noexcept { return lags_filled_ >= lags_wait_; }
  int lags_after_gap() const noexcept { return lags_needed_; }
  // The last na residuals of output j, newest first.
  const double* residual_lags(std::size_t j) const noexcept {
    return residual_lags_.col(static_cast<Eigen::Index>(j)).data();
  }
  // Output j's input regressors: nb per input, inputs in order (m nb values).
  const double* input_regressors(std::size_t j) const noexcept {
    return input_lags_.col(static_cast<Eigen::Index>(j * n_inputs_)).data();
  }

  // Real-time safe. A gap: the lags straddling it are invalid, so the bank
  // fills again from the next sample, and waits for its filters' memory.
  void gap() noexcept;
  // Real-time safe. Before push: at a (re)start, u becomes the input level
  // the regressors are taken about.
  void start_at(const double* u) noexcept;
  // Real-time safe. Sample k into the lags (for the row of k + 1).
  void push(const double* u, const double* residual) noexcept;

  // Setup: the residual needs no settling at the first start (the front end
  // skips no sample: every output is the controller's own prediction, or
  // the user said so), so the rows are used once the lags are filled.
  void start_settled() noexcept {
    lags_first_ = static_cast<int>(std::max(na_, nb_));
    if (lags_filled_ == 0) lags_wait_ = lags_first_;
  }

  void reset() noexcept;  // everything back to rest: the first start again
  void reset_output(std::size_t j) noexcept;  // output j's residual lags
  // Output j's residual lags, input regressors and filters from `part`.
  void adopt_output(const RegressorBank& part, std::size_t j);
  // What every output shares (fill count, input level) from `part`.
  void adopt_shared(const RegressorBank& part);

  template <class V>
  void visit_state(V&& v) {
    v(residual_lags_); v(input_lags_); v(channel_filters_); v(lags_filled_); v(lags_wait_); v(input_ref_);
  }

 private:
  std::size_t n_inputs_ = 0;
  std::size_t n_outputs_ = 0;
  std::size_t na_ = 0;
  std::size_t nb_ = 0;
  std::size_t first_output_ = 0;
  std::size_t end_output_ = 0;
  double pole_ = 0.0;
  Eigen::MatrixXd residual_lags_;  // na x n_outputs, newest first
  Eigen::MatrixXd input_lags_;     // nb x (n_outputs * n_inputs), output major
  // Per channel: q G_ji (one sample of the delay removed, so stepping it with
  // u(k) yields G_ji u at k+1), or empty for plain lags.
  std::vector<std::optional<DiscreteFilter>> channel_filters_;
  int lags_filled_ = 0;            // valid consecutive samples in the lags
  int lags_needed_ = 0;            // after a gap
  // At the first start. Where the residual starts settled, the filters
  // begin at rest at the first input level, the level its mismatch is taken
  // about, so G (u - u_ref) from rest is the mismatch's own regressor and a
  // wait for a memory that was never lost would only discard samples (the
  // first 985 of a real TCLab record with its controller's prediction, all
  // of one of 250). Where the front end skips a start-up transient of the
  // nominal model, the wait stays: that skip is capped at a tenth of the
  // record offline, and the rest of the transient would reach the
  // regressions (the paper's 4x4 tank). After a gap the filters restart at
  // rest while the plant still answers the inputs before it.
  int lags_first_ = 0;
  int lags_wait_ = 0;              // now: lags_first_ until a gap, then lags_needed_
  Eigen::VectorXd input_ref_;      // input level at (re)start
};

}  // namespace mpm
