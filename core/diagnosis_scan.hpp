// OVERVIEW
// The periodic diagnosis scan: the second live detector beside the
// sequential one (sequential_detector.hpp). Every `interval` usable samples
// the offline diagnosis (diagnosis.hpp, what `mpm diagnose` runs) looks at
// the most recent samples (at most `window`, fewer while they accumulate
// after start-up) at a per-look family level alpha_look; an output named by
// an accepted finding is raised, and cleared after `clear_after`
// consecutive looks that name nothing on it.
//
// Level. The controller's stated false-alarm rate R (per sample) is split
// once, here (share_rate): the scan gets `share` of it, the sequential
// detector the rest. Looks come every C samples at alpha_look = share R C,
// the diagnosis' family-wise level (Bonferroni over its candidates, times
// the independent held-out confirmation). A look spends that level twice,
// though: once on the process hypotheses, once on a changed disturbance
// model where no finding explains an output (diagnosis::Settings::alpha),
// so it raises falsely with probability at most 2 alpha_look, and the
// scan's false looks per sample are bounded by 2 share R whatever the
// dependence between looks (Boole's inequality: the union bound needs no
// independence). Measured, the scan raises 1.5 times its share and the
// sequential detector 0.4 times its own, so the whole path holds the
// stated rate (docs/method.md, "False alarms of the whole live path"). Overlapping
// windows make looks positively correlated, so the bound is conservative:
// the cost is power, a stricter level per look than a rate-exact threshold
// would need. A raise needs a clear in between, so false raises per output
// are at most false looks.
//
// This class is the schedule, the level and the raise/clear state; the
// samples (SampleRing) and the diagnosis itself are run by the caller:
// `mpm monitor --events` synchronously, mpmd on its diagnosis thread.
// Setup allocates; every other member is real-time safe.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "core/sequential_detector.hpp"

namespace mpm {

struct ScanSettings {
  std::size_t interval = 500;     // usable samples between looks; 0 = no scan
  std::size_t window = 3000;      // most recent samples a look diagnoses
  std::size_t min_samples = 1000; // first look once this many usable samples since settling
  double share = 0.5;             // of the controller's stated false-alarm rate (the rest: sequential)
  int clear_after = 2;            // consecutive looks without a finding on an output to clear it
  std::string validate() const;   // "" when valid
};

// The one place the stated rate is split between the two detectors:
// `sequential.false_alarms_per_year` holds the controller's rate on entry
// and the sequential detector's share on return; the scan's share is
// returned (per sample). A scan that is off takes nothing.
double share_rate(DetectorSettings& sequential, const ScanSettings& scan, double plant_sample_time);

class DiagnosisScan {
 public:
  DiagnosisScan() { settings_.interval = 0; }  // off
  // rate_per_sample: the scan's share (share_rate).
  DiagnosisScan(std::size_t outputs, const ScanSettings& settings, double rate_per_sample);

  bool enabled() const noexcept { return settings_.interval > 0; }
  // One usable (settled) sample has been recorded: true when a look is due now.
  bool on_ready_sample() noexcept;
  // The model settles again (start-up, long gap): the window grows afresh.
  void restart() noexcept { since_ready_ = 0; }
  // Samples the look due now covers: min(window, usable samples since settling).
  std::size_t look_length() const noexcept;
  double alpha_look() const noexcept { return alpha_look_; }

  // The outcome of one look: flagged[j] = an accepted finding names output j.
  // Calls on_edge(j, raised) for each output whose state changes.
  template <class OnEdge>
  void conclude(const std::vector<bool>& flagged, OnEdge&& on_edge) {
    ++looks_;
    for (std::size_t j = 0; j < raised_.size(); ++j) {
      const bool f = j < flagged.size() && flagged[j];
      if (f) {
        clean_[j] = 0;
        if (!raised_[j]) {
          raised_[j] = 1;
          on_edge(j, true);
        }
      } else if (raised_[j] && ++clean_[j] >= settings_.clear_after) {
        raised_[j] = 0;
        clean_[j] = 0;
        on_edge(j, false);
      }
    }
  }
  // The output's alarm is withdrawn from outside (the service is replaced).
  void lower(std::size_t output) noexcept {
    raised_[output] = 0;
    clean_[output] = 0;
  }
  // A look that was due but not run (mpmd: the diagnosis thread was busy).
  void skip() noexcept { ++skipped_; }

  bool raised(std::size_t output) const noexcept { return raised_[output] != 0; }
  std::uint64_t checkpoints() const noexcept { return checkpoints_; }  // looks due so far
  std::uint64_t looks() const noexcept { return looks_; }              // concluded
  std::uint64_t skipped() const noexcept { return skipped_; }
  const ScanSettings& settings() const noexcept { return settings_; }

  template <class V>
  void visit_state(V&& v) {  // checkpoint
    v(since_ready_); v(raised_); v(clean_); v(checkpoints_); v(looks_); v(skipped_);
  }

 private:
  ScanSettings settings_;
  double alpha_look_ = 0.0;
  std::size_t since_ready_ = 0;
  std::vector<std::uint8_t> raised_;
  std::vector<int> clean_;
  std::uint64_t checkpoints_ = 0;
  std::uint64_t looks_ = 0;
  std::uint64_t skipped_ = 0;
};

// The most recent samples (absolute inputs, then residuals; NaN = missing
// or not evidence), allocated at setup.
class SampleRing {
 public:
  SampleRing() = default;
  SampleRing(std::size_t rows, std::size_t inputs, std::size_t outputs);
  void record(const double* u, const double* residual) noexcept;  // real-time safe
  std::size_t capacity() const noexcept { return static_cast<std::size_t>(ring_.rows()); }
  std::size_t filled() const noexcept { return filled_; }
  // The last n rows (n <= filled()), oldest first, into out's first n rows
  // (out has capacity() rows and the ring's columns; no allocation).
  void copy_last(std::size_t n, Eigen::MatrixXd& out) const noexcept;

 private:
  Eigen::MatrixXd ring_;
  std::size_t inputs_ = 0;
  std::size_t head_ = 0;
  std::size_t filled_ = 0;
};

}  // namespace mpm
