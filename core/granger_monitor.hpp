// OVERVIEW
// Online Granger-causality monitor of model-plant mismatch (Chen, Xie & Su,
// Processes 2021, 9, 1976), one sample at a time, in fixed memory.
//
// For each output j the residual d~_j(k) is regressed on
//   [1, d~_j(k-1..k-na), L(q) u_1(k), ..., L(q) u_m(k)]
// where L(q) is a bank of nb orthonormal Laguerre filters with pole a, each
// with at least one sample of delay; a = 0 gives the paper's plain lags
// u_i(k-1..k-nb). A slow process has responses far longer than nb samples;
// with a near its dominant pole the same nb regressors cover them, which is
// what makes small, concealed mismatches detectable in a few thousand samples.
// The regressions are fitted by square-root recursive least squares with
// exponential forgetting, one shared update per output (nested_rls.hpp):
// the rows of [1, AR] are common to all of an output's models. From it come
//   * the AR-only residual variance Sigma1 and the full-model variance,
//   * the conditional Granger index of every input (all other inputs kept),
//     F_c(u_i -> d~_j) = ln(RSS without u_i / RSS full),
// and from its pairwise models [1, AR, u_i] (a small extra factor each),
//   * the paper's pairwise index F(u_i -> d~_j) = ln(Sigma1 / Sigma2),
//   * the AR coefficients the paper compares with N^-1: gamma(u_i -> d~_j).
//
// Model-filtered regressors (optional): given the nominal channel G_ji, the
// regressors of input i in output j's models are lags of G_ji u_i instead of
// u_i. Still the past of u_i (G_ji is strictly causal), but a gain mismatch
// dG = (k - 1) G_ji then lies in the span of two regressors instead of being
// smeared over nb lags and the residual's own AR part, so the test has far
// more power on the slow, closed-loop data MPCs produce. Channels the model
// says are zero keep plain lags (a missing channel has no shape to borrow).
//
// Tests: each index becomes a likelihood-ratio statistic LR = n_eq * F,
// chi-square with nb degrees of freedom under "no causality", where n_eq =
// (sum w)^2 / sum w^2 is the equivalent sample count of the forgetting
// weights (= n for lambda = 1). The alarm threshold is precomputed at setup
// from the per-channel false-alarm probability, so the hot path compares
// numbers; p-values are computed on request (publishing, reports).
//
// Loops: the joint test of all inputs together (AR-only vs full model,
// m*nb dof) raises the loop; it keeps its power when closed-loop inputs are
// nearly collinear and no single input's conditional test can tell them
// apart. Then the paper's two indices name the channel (located_by_gamma):
// of the channels whose AR part matches N^-1, the one with the largest F.
//
// Alarms: a channel is raised when its conditional LR exceeds the threshold
// for `raise_after` consecutive samples, cleared when it stays below the
// clear threshold (a lower, hysteresis level) for `clear_after` samples.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "core/nested_rls.hpp"
#include "core/transfer_function.hpp"

namespace mpm {

struct MonitorSettings {
  int ar_order = 10;             // na: lags of the residual
  int input_order = 10;          // nb: lags (basis functions) of each input
  double input_pole = 0.0;       // Laguerre pole a in [0, 0.99) of the input
                                 // basis: 0 = plain lags u(k-1..k-nb), as in the
                                 // paper; near the process's dominant pole, nb
                                 // functions span a memory of ~nb/(1-a) samples
  double forgetting = 0.999;     // lambda in (0, 1]; 1 = growing window
  double false_alarm = 1e-3;     // per-channel, per-test probability alpha of
                                 // exceeding the raise threshold under H0
  double clear_ratio = 0.5;      // clear threshold = clear_ratio * raise threshold
  int raise_after = 20;          // consecutive samples above to raise
  int clear_after = 100;         // consecutive samples below to clear
  int warmup = 0;                // samples before any test (0 = automatic:
                                 // 10 x number of regressors)
  double gamma_lambda = 0.1;     // paper's lambda: gamma < lambda^2 locates

  // Empty string when valid, else what is wrong (names the field and range).
  std::string validate() const;
};

// What one update did with a sample.
enum class SampleStatus : std::uint8_t {
  kUsed,        // entered the statistics
  kMissing,     // a NaN/inf in u or residual: skipped, lags restart after it
  kWarmingUp,   // filled lags only (after start or a gap)
};

struct ChannelStats {
  double f_pairwise = 0.0;     // ln(Sigma1 / Sigma2), paper's index
  double f_conditional = 0.0;  // ln(RSS without u_i / RSS full)
  double lr_pairwise = 0.0;    // n_eq * f_pairwise
  double lr_conditional = 0.0; // n_eq * f_conditional
  double gamma = 0.0;          // noise-model index (NaN when N is unknown)
  bool alarm = false;          // raised by its own conditional test
  bool located_by_gamma = false;  // the loop is raised, no input passes its
                               // own test, this channel's gamma < lambda^2 and
                               // its pairwise F is the largest of those: the
                               // paper's locating rule
  int above = 0;               // consecutive samples above the raise level
  int below = 0;               // consecutive samples below the clear level
  template <class V>
  void visit_state(V&& v) {  // every field: a checkpoint restores them all
    v(f_pairwise); v(f_conditional); v(lr_pairwise); v(lr_conditional); v(gamma); v(alarm);
    v(located_by_gamma); v(above); v(below);
  }
};

struct LoopStats {
  double lr_joint = 0.0;         // all inputs together vs AR only, m*nb dof
  bool joint_alarm = false;      // the joint test's own alarm state
  int above = 0;                 // hysteresis counters of the joint test
  int below = 0;
  double sigma1 = 0.0;           // AR-only residual variance (weighted)
  double sigma_full = 0.0;       // full-model residual variance (weighted)
  double residual_variance = 0.0;// weighted variance of d~ about its mean
  bool alarm = false;            // joint test raised, or any channel raised
  bool diverging = false;        // residual variance growing without bound
  template <class V>
  void visit_state(V&& v) {
    v(lr_joint); v(joint_alarm); v(above); v(below); v(sigma1); v(sigma_full); v(residual_variance);
    v(alarm); v(diverging);
  }
};

struct MonitorCounters {
  std::uint64_t samples = 0;     // update() calls
  std::uint64_t used = 0;        // samples that entered the statistics
  std::uint64_t missing = 0;     // samples with NaN/inf skipped
  std::uint64_t gaps = 0;        // runs of missing samples
  template <class V>
  void visit_state(V&& v) {
    v(samples); v(used); v(missing); v(gaps);
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

class GrangerMonitor {
 public:
  // Allocates everything. `n_inverse_ar[j]`, when given, holds the coefficients
  // of 1 - N_j^-1 (noise_filter.hpp) for output j, at least ar_order long;
  // without it gamma is NaN for that output. `reference_variance[j]`, when
  // given and > 0, is the variance the residual of output j has with a
  // matched model (N's output variance): a residual far above it means the
  // loop diverges. Throws std::invalid_argument on invalid settings or sizes.
  // `channel_models`, when given, has n_outputs * n_inputs entries (output
  // major): the nominal G_ji for model-filtered regressors, nullopt or a zero
  // channel for plain lags.
  GrangerMonitor(std::size_t n_inputs, std::size_t n_outputs, const MonitorSettings& settings,
                 std::vector<std::optional<std::vector<double>>> n_inverse_ar = {},
                 std::vector<double> reference_variance = {},
                 const std::vector<std::optional<DiscreteTf>>& channel_models = {},
                 OutputRange modelled = {});

  // Real-time safe: no allocation, no exceptions. u: n_inputs values at time
  // k, residual: n_outputs values of d~ at time k. Returns what was done.
  SampleStatus update(const double* u, const double* residual) noexcept;

  // Statistics as of the last update (refreshed every used sample).
  const ChannelStats& channel(std::size_t output, std::size_t input) const noexcept {
    return channels_[output * n_inputs_ + input];
  }
  const LoopStats& loop(std::size_t output) const noexcept { return loops_[output]; }
  const MonitorCounters& counters() const noexcept { return counters_; }

  // Equivalent sample count behind the current statistics.
  double effective_samples() const noexcept { return n_eq_; }
  double raise_threshold() const noexcept { return lr_raise_; }
  double joint_raise_threshold() const noexcept { return lr_joint_raise_; }
  // p-value of a loop's joint LR (chi-square, n_inputs * nb dof).
  double joint_p_value(double lr) const noexcept;
  double clear_threshold() const noexcept { return lr_clear_; }
  bool ready() const noexcept;  // warm-up over

  // p-value of an LR statistic under H0 (chi-square, nb dof). Not for the hot
  // path (evaluates an incomplete gamma function), but allocation free.
  double p_value(double lr) const noexcept;

  // Full-model coefficients of output j: [intercept, AR (na), u_1 (nb), ...].
  // Allocation free; writes into `out` (size n_regressors()).
  void full_coefficients(std::size_t output, Eigen::Ref<Eigen::VectorXd> out) const noexcept;
  // AR coefficients of the pairwise model [1, AR, u_i] of (output, input).
  void pairwise_ar_coefficients(std::size_t output, std::size_t input,
                                Eigen::Ref<Eigen::VectorXd> out) const noexcept;

  std::size_t n_inputs() const noexcept { return n_inputs_; }
  std::size_t n_outputs() const noexcept { return n_outputs_; }
  std::size_t n_regressors() const noexcept { return 1 + na_ + n_inputs_ * nb_; }
  const MonitorSettings& settings() const noexcept { return settings_; }

  // Forgets everything learnt: statistics, lags, alarms (counters are kept).
  void reset() noexcept;

  // The outputs this monitor models (all unless constructed with a range);
  // statistics of the others stay at their initial values.
  std::size_t first_modelled_output() const noexcept { return first_output_; }
  std::size_t end_modelled_output() const noexcept { return end_output_; }
  // Takes over the state of the outputs `part` models from `part`, a monitor
  // of the same plant and settings fed the same samples. Not real-time
  // (copies factors); throws std::invalid_argument when they do not match.
  void adopt_outputs(const GrangerMonitor& part);

  // Calls v(member) for every member that changes after setup, in a fixed
  // order: what a checkpoint saves and restores (daemon/mpmd/checkpoint.hpp).
  // Settings, thresholds and scratch are rebuilt by the constructor.
  template <class V>
  void visit_state(V&& v) {
    v(residual_lags_); v(input_lags_); v(channel_filters_); v(lags_filled_); v(input_ref_);
    v(regressions_); v(channels_); v(loops_); v(counters_); v(in_gap_); v(used_since_reset_);
    v(sum_w_); v(sum_w2_); v(n_eq_); v(mean_fast_); v(var_fast_); v(var_baseline_);
  }

 private:
  void absorb_sample(const double* residual) noexcept;
  void push_lags(const double* u, const double* residual) noexcept;
  void update_statistics() noexcept;
  template <typename Stats>
  void update_hysteresis(Stats& s, double lr, double raise, double clear, bool& alarm) noexcept;
  void update_divergence(const double* residual) noexcept;

  MonitorSettings settings_;
  std::size_t n_inputs_;
  std::size_t n_outputs_;
  std::size_t first_output_ = 0;   // modelled outputs [first_output_, end_output_)
  std::size_t end_output_ = 0;
  std::size_t na_;
  std::size_t nb_;
  int warmup_;

  // Residual lags per output, newest first (na_ each), shifted each sample;
  // input regressor states per (output, input) channel (nb_ each, output
  // major): the basis applied to u_i or to G_ji u_i, for the next sample.
  Eigen::MatrixXd residual_lags_;  // na_ x n_outputs
  Eigen::MatrixXd input_lags_;     // nb_ x (n_outputs * n_inputs)
  // Per channel: q G_ji (one sample of the delay removed, so stepping it with
  // u(k) yields G_ji u at k+1), or empty for plain lags.
  std::vector<std::optional<DiscreteFilter>> channel_filters_;
  int lags_filled_ = 0;            // valid consecutive samples in the lags
  int filter_settle_ = 0;          // samples for the model filters to settle
  int lags_needed_ = 0;            // samples to fill lags / settle the basis
  Eigen::VectorXd input_ref_;      // input level at (re)start: the basis sees
                                   // u - input_ref_, so its zero state is at rest

  // One per output: the full model [1, AR, u_1 .. u_m] and the pairwise
  // models [1, AR, u_i] in one shared update (nested_rls.hpp).
  std::vector<NestedRls> regressions_;
  mutable Eigen::VectorXd pair_coef_;  // scratch: [1, AR] coefficients of a pairwise model
  SqrtRls::Matrix scratch_;        // scratch for conditional RSS
  // Scratch: one output's RSS ratios [joint, conditional (m), pairwise (m)]
  // and their logarithms, taken in one vectorised call.
  Eigen::ArrayXd rss_ratios_;
  Eigen::ArrayXd log_ratios_;

  std::vector<std::optional<Eigen::VectorXd>> n_inverse_ar_;
  std::vector<ChannelStats> channels_;
  std::vector<LoopStats> loops_;
  MonitorCounters counters_;
  bool in_gap_ = false;
  std::uint64_t used_since_reset_ = 0;

  double sum_w_ = 0.0;   // sum of forgetting weights
  double sum_w2_ = 0.0;  // sum of squared weights
  double n_eq_ = 0.0;
  double lr_raise_ = 0.0;
  double lr_clear_ = 0.0;
  double lr_joint_raise_ = 0.0;
  double lr_joint_clear_ = 0.0;
  // Divergence detection per output: running mean and variance of d~ with a
  // short memory, and the quietest variance seen (the baseline).
  Eigen::VectorXd mean_fast_;
  Eigen::VectorXd var_fast_;
  Eigen::VectorXd var_baseline_;
  Eigen::VectorXd var_reference_;  // from the noise model; 0 = unknown
};

}  // namespace mpm
