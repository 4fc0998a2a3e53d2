#include "core/diagnosis_scan.hpp"

#include <algorithm>
#include <limits>
#include <sstream>

namespace mpm {

std::string ScanSettings::validate() const {
  std::ostringstream e;
  if (interval > 0) {
    if (interval < 50 || interval > 10000000) e << "scan_interval must be 0 (off) or in 50..10000000 samples, got " << interval << "; ";
    if (window < 200 || window > 1000000) e << "scan window must be in 200..1000000 samples, got " << window << "; ";
    if (min_samples < 200 || min_samples > window) e << "scan min_samples must be in 200..window, got " << min_samples << "; ";
    if (!(share > 0.0 && share < 1.0)) e << "scan share of the false-alarm rate must be in (0, 1), got " << share << "; ";
    if (clear_after < 1 || clear_after > 1000) e << "scan clear_after must be in 1..1000 looks, got " << clear_after << "; ";
  }
  return e.str();
}

double share_rate(DetectorSettings& sequential, const ScanSettings& scan, double plant_sample_time) {
  if (sequential.sample_time <= 0.0 && plant_sample_time > 0.0) sequential.sample_time = plant_sample_time;
  const double share = scan.interval > 0 ? scan.share : 0.0;
  const double scan_rate = share * sequential.rate_per_sample();
  sequential.false_alarms_per_year *= 1.0 - share;
  return scan_rate;
}

DiagnosisScan::DiagnosisScan(std::size_t outputs, const ScanSettings& settings, double rate_per_sample)
    : settings_(settings),
      // alpha_look = share R C (see the overview); capped below 1 for a level.
      alpha_look_(std::min(0.5, rate_per_sample * static_cast<double>(settings.interval))),
      raised_(outputs, 0),
      clean_(outputs, 0) {}

bool DiagnosisScan::on_ready_sample() noexcept {
  if (settings_.interval == 0) return false;
  ++since_ready_;
  const bool due = since_ready_ >= settings_.min_samples && (since_ready_ - settings_.min_samples) % settings_.interval == 0;
  checkpoints_ += due ? 1 : 0;
  return due;
}

std::size_t DiagnosisScan::look_length() const noexcept { return std::min(settings_.window, since_ready_); }

SampleRing::SampleRing(std::size_t rows, std::size_t inputs, std::size_t outputs)
    : ring_(Eigen::MatrixXd::Constant(static_cast<Eigen::Index>(rows), static_cast<Eigen::Index>(inputs + outputs),
                                      std::numeric_limits<double>::quiet_NaN())),
      inputs_(inputs) {}

void SampleRing::record(const double* u, const double* residual) noexcept {
  const std::size_t rows = capacity();
  if (rows == 0) return;
  const auto r = static_cast<Eigen::Index>(head_);
  const auto cols = static_cast<std::size_t>(ring_.cols());
  for (std::size_t i = 0; i < inputs_; ++i) ring_(r, static_cast<Eigen::Index>(i)) = u[i];
  for (std::size_t j = inputs_; j < cols; ++j) ring_(r, static_cast<Eigen::Index>(j)) = residual[j - inputs_];
  head_ = head_ + 1 == rows ? 0 : head_ + 1;
  if (filled_ < rows) ++filled_;
}

void SampleRing::copy_last(std::size_t n, Eigen::MatrixXd& out) const noexcept {
  const std::size_t rows = capacity();
  if (rows == 0) return;
  n = std::min(n, filled_);
  // head_ is the next row to write: the newest is head_ - 1.
  const std::size_t start = (head_ + rows - n) % rows;
  for (std::size_t k = 0; k < n; ++k)
    out.row(static_cast<Eigen::Index>(k)) = ring_.row(static_cast<Eigen::Index>((start + k) % rows));
}

}  // namespace mpm
