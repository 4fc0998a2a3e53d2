// The Granger monitor's settings and what it reports: per-sample status,
// per-channel and per-loop statistics, counters, the outputs it models.
// Plain data, shared by the monitor (granger_monitor.hpp), its front end
// and everything that prints, publishes or checkpoints the statistics.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "core/sequential_detector.hpp"

namespace mpm {

struct MonitorSettings {
  int ar_order = 10;             // na: lags of the residual
  int input_order = 10;          // nb: lags (basis functions) of each input
  double input_pole = 0.0;       // Laguerre pole a in [0, 0.99) of the input
                                 // basis: 0 = plain lags u(k-1..k-nb), as in the
                                 // paper; near the process's dominant pole, nb
                                 // functions span a memory of ~nb/(1-a) samples
  double forgetting = 0.999;     // lambda in (0, 1]; 1 = growing window
  double false_alarm = 1e-3;     // probability alpha of the end-of-record test
                                 // (record_verdict) per channel and test, and the
                                 // level at which a raise's conditional score
                                 // names a channel on its own
  DetectorSettings detector{};   // live alarms: stated rate per unit time
  double outlier_limit = 10.0;   // skip a sample whose residual moves more than
                                 // this many robust standard deviations of its
                                 // recent one-step changes (0 = never)
  int warmup = 0;                // samples before any test (0 = automatic:
                                 // 10 x number of regressors)
  double gamma_lambda = 0.1;     // paper's lambda: gamma < lambda^2 locates

  // One row per setting (field_table.hpp), with the detector's settings a
  // monitor file sets (false_alarms_per_year, sample_time,
  // crossing_constant, detector_thresholds) lifted from DetectorSettings.
  static const std::vector<FieldRow<MonitorSettings>>& fields();
  // Every setting out of its range (each range is in one row), then the
  // detector's own errors.
  std::vector<FieldError> errors() const;
  // Empty string when valid, else what is wrong (names the field and range).
  std::string validate() const { return joined(errors()); }
  bool operator==(const MonitorSettings&) const = default;
};

// What one update did with a sample.
enum class SampleStatus : std::uint8_t {
  kUsed,        // entered the statistics
  kMissing,     // a NaN/inf in u or residual: skipped, lags restart after it
  kWarmingUp,   // filled lags only (after start or a gap)
  kOutlier,     // a residual beyond the robust bound: skipped, counted
};

struct ChannelStats {
  double f_pairwise = 0.0;     // ln(Sigma1 / Sigma2), paper's index
  double f_conditional = 0.0;  // ln(RSS without u_i / RSS full)
  double lr_pairwise = 0.0;    // (n_eq - p_pair) * f_pairwise, p_pair = 1 + na + nb
  double lr_conditional = 0.0; // (n_eq - p_full) * f_conditional, p_full = 1 + na + m nb
  double gamma = 0.0;          // noise-model index (NaN when N is unknown)
  double score_conditional = 0.0;  // at the output's last raise: the
                               // conditional score statistic of this input
                               // given the others (chi-square, nb dof)
  bool alarm = false;          // the channel named in a raised output
  bool located_by_gamma = false;  // named by the paper's rule (gamma < lambda^2,
                               // largest pairwise F) because no input's
                               // conditional score stood out on its own
  template <class V>
  void visit_state(V&& v) {  // every field: a checkpoint restores them all
    v(f_pairwise); v(f_conditional); v(lr_pairwise); v(lr_conditional); v(gamma); v(score_conditional);
    v(alarm); v(located_by_gamma);
  }
};

struct LoopStats {
  double lr_joint = 0.0;         // all inputs together vs AR only, m*nb dof
  double score = 0.0;            // at the last raise: T_W of the raising window
  double score_threshold = 0.0;  // its threshold h_W
  double score_window = 0.0;     // its memory W (samples)
  double sigma1 = 0.0;           // AR-only residual variance (weighted)
  double sigma_full = 0.0;       // full-model residual variance (weighted)
  double residual_variance = 0.0;// weighted variance of d~ about its mean
  bool alarm = false;            // raised by the sequential detector
  bool diverging = false;        // residual variance growing without bound
  template <class V>
  void visit_state(V&& v) {
    v(lr_joint); v(score); v(score_threshold); v(score_window); v(sigma1); v(sigma_full); v(residual_variance);
    v(alarm); v(diverging);
  }
};

struct MonitorCounters {
  std::uint64_t samples = 0;     // update() calls
  std::uint64_t used = 0;        // samples that entered the statistics
  std::uint64_t missing = 0;     // samples with NaN/inf skipped
  std::uint64_t gaps = 0;        // runs of missing samples
  std::uint64_t outliers = 0;    // samples skipped beyond the robust bound
  std::uint64_t resets = 0;      // outputs restarted after non-finite statistics or,
                                 // with forgetting, at the end of a divergence
  std::uint64_t raises = 0;      // raise events of the sequential detector
  template <class V>
  void visit_state(V&& v) {
    v(samples); v(used); v(missing); v(gaps); v(outliers); v(resets); v(raises);
  }
};

// The outputs a monitor models: [first, first + count), clipped to the
// plant's outputs. A monitor of a part of the outputs still takes whole
// samples (every input and residual, so it skips gaps and settles exactly as
// the whole monitor does) and its statistics for those outputs equal the
// whole monitor's bit for bit: parts can run on separate threads over a
// recording and be merged (adopt_outputs).
struct OutputRange {
  std::size_t first = 0;
  std::size_t count = static_cast<std::size_t>(-1);
};

}  // namespace mpm
