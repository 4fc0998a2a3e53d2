// OVERVIEW
// The soak of issue 12 (item 8): the real monitoring service (mpmd's
// MonitorService: size check, sequence tracking, gap filling, settling,
// residuals, GrangerMonitor, alarm edges, status) fed a long stream of
// stretches, each a kind of trouble a plant network gives a monitor:
//   matched      the plant equals the model
//   mismatched   G21 (u1 -> y2) gain x 1.3 for the whole stretch (the truth)
//   gaps         sequence numbers skipped (1..30 at a time; never delivered)
//   nan          bursts of 1..20 samples with a NaN in one input or output
//   outliers     single samples with 1e6 or 1e100 added to an output, or 1e6
//                to an input (sensor glitches)
//   frozen       the inputs held (no excitation: input regressors collinear
//                with the intercept)
//   huge / tiny  every value (inputs, outputs, prediction, noise) x 1e8 / 1e-8
// Every disturbance lies in [10 %, 50 %) of its stretch; the rest is clean,
// so each stretch ends with the service recovering from it. Samples carry
// the controller's prediction sim_y, so the residual is y - sim_y whatever
// the scale (a model prediction from scaled inputs would be a mismatch).
//
// What is measured, and what "the same window" means. At the end of every
// stretch each output's recursive statistics are compared with a batch
// least-squares fit (Householder QR, tests/support/batch_qr.hpp) of the
// SAME WINDOW: every regressor row the output's factor absorbed since its
// last start (the service's start, or a reset after non-finite statistics),
// i.e. the samples the monitor used, and not the ones it skipped (gaps, NaN,
// outliers, settling, lag refill), each weighted lambda^(number of used
// samples since), plus the prior delta I. Rows older than
// ln(1e-30)/ln(lambda) used samples are left out: their weight is below
// 1e-30, under double precision even for rows 1e8 larger than the newest.
// The rows are read from the monitor's own regressor registers (through its
// checkpoint visitor) before each update, so the comparison checks what the
// recursion made of the rows (numerical recovery after 1e8, 1e-8, 1e100,
// frozen inputs), not how the rows were built (tests/core checks that
// against lags built independently). Compared: the RSS ratios behind every
// F (conditional and pairwise, |delta F|), sigma1 / sigma_full and the
// full model's RSS (relative). The largest of these is the stretch's
// deviation.
//
// Also: every statistic finite after every sample and in every status;
// alarm edges per stretch and channel (the truth: raised on u1 -> y2 in a
// mismatched stretch; in the others nothing raised outside the disturbance
// window and nothing still raised at the end; raises while the disturbed
// data come are counted apart: data that bad are no evidence either way,
// and the figure says how often the detector reacts to them); resident
// memory (/proc/self/statm) after every stretch.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace mpm::bench {

enum class SoakKind : std::uint8_t { kMatched, kMismatched, kGaps, kNan, kOutliers, kFrozen, kHuge, kTiny };
const char* soak_kind_name(SoakKind kind) noexcept;

struct SoakOptions {
  std::uint64_t samples = 100'000'000;  // generated samples (sequence numbers), gaps included
  std::uint64_t stretch = 25'000;       // samples per stretch
  std::uint64_t seed = 1;
  // Called after every stretch with the samples done so far (may be empty).
  std::function<void(std::uint64_t done, std::uint64_t total)> progress;
};

struct SoakStretch {
  SoakKind kind = SoakKind::kMatched;
  std::uint64_t first_sample = 0;
  std::uint64_t samples = 0;
  bool mismatched = false;           // the truth
  int raises_true = 0;               // raise edges on u1 -> y2
  int raises_other = 0;              // raise edges on any other channel, outside the disturbance
  std::int64_t first_clean_raise = -1;  // samples into the stretch of the first raise_other, -1: none
  int first_clean_output = -1, first_clean_input = -1;  // its channel (0-based)
  int raises_disturbed = 0;          // raise edges while disturbed data came (gaps, NaN, outliers,
                                     // frozen, x 1e8, x 1e-8), any channel but the mismatch's
  bool raised_at_end = false;        // any channel raised when the stretch ended
  bool diverging_at_end = false;     // any output flagged diverging (no verdict) when it ended
  double deviation = 0.0;            // largest deviation from the batch fit at its end
  double rss_kb = 0.0;               // resident memory after it
};

struct SoakFaults {
  std::uint64_t gap_events = 0, missing = 0;   // sequence gaps, samples never delivered
  std::uint64_t nan_bursts = 0, nan_samples = 0;
  std::uint64_t outliers = 0, outliers_1e100 = 0;
  std::uint64_t frozen = 0, huge = 0, tiny = 0;  // samples
  std::uint64_t mismatched = 0;                  // samples
  std::uint64_t stretches = 0;                   // mismatched, frozen, huge and tiny stretches
  std::uint64_t events() const noexcept;         // gap events + NaN bursts + outliers + disturbed stretches
};

struct SoakReport {
  std::uint64_t samples = 0;         // generated
  std::uint64_t delivered = 0;       // given to the service
  std::uint64_t used = 0;            // entered the statistics
  std::uint64_t checks = 0;          // comparisons with the batch fit
  std::uint64_t nonfinite = 0;       // non-finite statistics seen (samples x values)
  std::uint64_t statuses = 0;        // status messages filled and checked
  std::uint64_t log_lines = 0;
  double max_deviation = 0.0;        // over every check
  double rss_first_kb = 0.0;         // after the first stretch
  double rss_max_growth_kb = 0.0;    // largest RSS after any later stretch, minus the first
  double seconds = 0.0;              // wall clock
  // What the service and the monitor counted.
  std::uint64_t service_gaps = 0, service_missing = 0, service_nan = 0, monitor_outliers = 0,
                monitor_resets = 0, monitor_raises = 0;
  SoakFaults faults;
  std::vector<SoakStretch> stretches;
};

// Runs the soak in this process (Wood-Berry plant, config/wood-berry.yaml's
// model built in). Throws std::runtime_error when the monitor's state layout
// is not what the probe expects.
SoakReport run_soak(const SoakOptions& options);

// Resident set size of this process in kB (/proc/self/statm), 0 if unknown.
double resident_kb();

}  // namespace mpm::bench
