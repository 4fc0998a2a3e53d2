#include "core/outlier_screen.hpp"

#include <algorithm>
#include <cmath>

namespace mpm {
namespace {

// The mean absolute one-step change is learnt over this many samples before
// any is rejected, then followed with a ~200-sample memory; this many
// consecutive rejections are a level shift, accepted.
constexpr std::uint64_t kOutlierLearn = 50;
constexpr double kJumpMemory = 0.995;
constexpr int kOutlierRunAccept = 5;
// Mean absolute value of a standard normal: mean |change| / this = sigma.
constexpr double kMeanAbsNormal = 0.7978845608;

}  // namespace

OutlierScreen::OutlierScreen(std::size_t n_outputs, double limit)
    : limit_(limit),
      last_good_(n_outputs, 0.0),
      jump_scale_(n_outputs, 0.0),
      outlier_run_(n_outputs, 0),
      screened_(n_outputs, 0),
      clean_(n_outputs, 0.0) {}

bool OutlierScreen::screen(const double* residual) noexcept {
  if (limit_ == 0.0) return false;
  bool outlier = false;
  // Every output, modelled or not: a monitor of a part of the outputs skips
  // exactly the samples the whole monitor skips.
  const std::size_t n_outputs = clean_.size();
  for (std::size_t j = 0; j < n_outputs; ++j) {
    clean_[j] = residual[j];
    const double jump = std::abs(residual[j] - last_good_[j]);
    const std::uint64_t n = screened_[j]++;
    double& scale = jump_scale_[j];
    if (n == 0) {  // first sample after a (re)start: nothing to compare with
      last_good_[j] = residual[j];
      continue;
    }
    if (n < kOutlierLearn) {  // learning the scale: plain running mean
      scale += (jump - scale) / static_cast<double>(n);
      last_good_[j] = residual[j];
      continue;
    }
    const double limit = limit_ * scale / kMeanAbsNormal;
    if (jump > limit && outlier_run_[j] < kOutlierRunAccept) {
      ++outlier_run_[j];
      clean_[j] = last_good_[j];
      outlier = true;
      continue;
    }
    outlier_run_[j] = 0;
    scale = kJumpMemory * scale + (1.0 - kJumpMemory) * std::min(jump, limit);
    last_good_[j] = residual[j];
  }
  if (outlier) {
    // Nothing of this sample enters any output's statistics; the outputs
    // that were fine keep their value as the last good one.
    for (std::size_t j = 0; j < n_outputs; ++j)
      if (clean_[j] == residual[j] && outlier_run_[j] == 0) last_good_[j] = residual[j];
  }
  return outlier;
}

void OutlierScreen::reset() noexcept {
  std::fill(jump_scale_.begin(), jump_scale_.end(), 0.0);
  std::fill(outlier_run_.begin(), outlier_run_.end(), 0);
  std::fill(screened_.begin(), screened_.end(), 0);
}

void OutlierScreen::reset_output(std::size_t j) noexcept {
  jump_scale_[j] = 0.0;
  outlier_run_[j] = 0;
  screened_[j] = 0;
}

void OutlierScreen::adopt_output(const OutlierScreen& part, std::size_t j) noexcept {
  last_good_[j] = part.last_good_[j];
  jump_scale_[j] = part.jump_scale_[j];
  outlier_run_[j] = part.outlier_run_[j];
  screened_[j] = part.screened_[j];
}

}  // namespace mpm
