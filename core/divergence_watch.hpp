// Divergence of a loop, per output: the residual's short-memory variance
// far above the matched-model variance (when the noise model gives it) or
// far above its own quietest level. A causality verdict on a loop that is
// not stationary would be meaningless (paper Sec. 4.2.4). With forgetting,
// the quietest level is that of the statistics' own memory, so the flag
// ends when the loop settles again; with lambda = 1 it stays.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Dense>

namespace mpm {

class DivergenceWatch {
 public:
  DivergenceWatch() = default;
  // reference_variance: empty or one per output; a non-finite or
  // non-positive entry means unknown.
  DivergenceWatch(std::size_t n_outputs, const std::vector<double>& reference_variance, double forgetting);

  // Real-time safe. One used sample's residual r of output j, `used` samples
  // of it used before this one; `diverging` is the loop's flag, updated.
  // True when a divergence ended with this sample (with forgetting): the
  // statistics still hold the diverging samples, so the output must start
  // again.
  bool update(std::size_t j, double r, std::uint64_t used, bool& diverging) noexcept;

  void reset() noexcept;
  void reset_output(std::size_t j) noexcept;
  void adopt_output(const DivergenceWatch& part, std::size_t j) noexcept;

  template <class V>
  void visit_state(V&& v) {
    v(mean_fast_); v(var_fast_); v(var_baseline_);
  }

 private:
  double forgetting_ = 1.0;
  // Running mean and variance of d~ with a short memory, and the quietest
  // variance seen (the baseline).
  Eigen::VectorXd mean_fast_;
  Eigen::VectorXd var_fast_;
  Eigen::VectorXd var_baseline_;
  Eigen::VectorXd var_reference_;  // from the noise model; 0 = unknown
};

}  // namespace mpm
