// Outlier screening of the residuals, one sample at a time: a sample whose
// residual jumps by more than `limit` robust standard deviations of its
// recent one-step changes is an outlier (the monitor skips it and counts
// it). The scale is the mean absolute one-step change, learnt over the
// first samples after a (re)start, then followed with a short memory and
// clipped at the limit so an outlier cannot inflate it; a run of
// consecutive rejections is a level shift and is accepted.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace mpm {

class OutlierScreen {
 public:
  OutlierScreen() = default;
  // limit: robust standard deviations (0 = never an outlier).
  OutlierScreen(std::size_t n_outputs, double limit);

  // Real-time safe. True when the sample is an outlier: then clean() holds
  // the residual with the outlying outputs at their last good value.
  bool screen(const double* residual) noexcept;
  const double* clean() const noexcept { return clean_.data(); }

  // Every output learns its scale again (the last good values are kept:
  // the first sample after the restart overwrites them).
  void reset() noexcept;
  void reset_output(std::size_t j) noexcept;
  void adopt_output(const OutlierScreen& part, std::size_t j) noexcept;

  template <class V>
  void visit_state(V&& v) {
    v(last_good_); v(jump_scale_); v(outlier_run_); v(screened_);
  }

 private:
  double limit_ = 0.0;
  std::vector<double> last_good_;
  std::vector<double> jump_scale_;          // mean |one-step change|
  std::vector<int> outlier_run_;            // consecutive rejections
  std::vector<std::uint64_t> screened_;     // samples screened since the output's (re)start
  std::vector<double> clean_;               // the cleaned sample (not state)
};

}  // namespace mpm
