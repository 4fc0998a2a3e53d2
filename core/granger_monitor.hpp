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
// Alarms: a sequential detector per output (sequential_detector.hpp): the
// score test of all inputs against the AR-only model, accumulated over
// several memories at once, with thresholds derived from a stated false-
// alarm rate per unit time for the whole controller. Beside it, a focused
// score of m dof (per input, the lags of G_ji u_i weighted by the nominal
// noise model's whitening polynomial: the direction of a gain mismatch
// after the AR reference), sharing the rate half and half (Bonferroni):
// its threshold is far lower than the m nb-dof one's (measured on Wood-
// Berry G21 x 1.2: raised at 3000-4200 samples instead of 5000-12 000;
// the lag-0 column alone carried almost none of the signal, T ~ 5).
// The score accumulates from the factor's first sample and is tested
// after the burn-in. When an output is
// raised, the channel is named by the best evidence: the conditional score
// of each input given the others (from the raising window's score), or, if
// none stands out on its own, the paper's gamma rule.
//
// Robustness: a sample whose residual jumps by more than `outlier_limit`
// robust standard deviations of its recent one-step changes is skipped and
// counted (the residual lags hold the previous value); an output whose
// statistics go non-finite starts again from its prior, counted. With
// forgetting, "diverging" holds while the residual's variance is far above
// its quietest level within the statistics' memory, and the output starts
// again when it ends (its statistics hold the diverging samples).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "core/nested_rls.hpp"
#include "core/sequential_detector.hpp"
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
  double false_alarm = 1e-3;     // probability alpha of the end-of-record test
                                 // (record_verdict) per channel and test, and the
                                 // level at which a raise's conditional score
                                 // names a channel on its own
  DetectorSettings detector;     // live alarms: stated rate per unit time
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
  double lr_pairwise = 0.0;    // n_eq * f_pairwise
  double lr_conditional = 0.0; // n_eq * f_conditional
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
  // End-of-record test thresholds (chi-square quantiles at false_alarm).
  double raise_threshold() const noexcept { return lr_raise_; }
  double joint_raise_threshold() const noexcept { return lr_joint_raise_; }
  // p-value of a loop's joint LR (chi-square, n_inputs * nb dof).
  double joint_p_value(double lr) const noexcept;
  // The live detector (thresholds, windows, last statistics): the score of
  // all m nb input regressors, and the focused one of the newest regressor
  // of each input along its channel's gain direction (m dof), each with
  // half the stated rate.
  const SequentialDetector& detector() const noexcept { return detector_; }
  const SequentialDetector& focused_detector() const noexcept { return focused_; }
  bool ready() const noexcept;  // warm-up over

  // p-value of an LR statistic under H0 (chi-square, nb dof). Not for the hot
  // path (evaluates an incomplete gamma function), but allocation free.
  double p_value(double lr) const noexcept;

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
    v(output_used_); v(output_sum_w_); v(last_good_); v(jump_scale_); v(outlier_run_); v(screened_);
    v(refresh_last_); v(refresh_count_); v(refresh_tick_); v(refresh_cursor_);
    detector_.visit_state(v);
    focused_.visit_state(v);
    for (Eigen::MatrixXd& m : info_last_) v(m);
  }

 private:
  void absorb_sample(const double* residual) noexcept;
  void push_lags(const double* u, const double* residual) noexcept;
  void update_statistics() noexcept;
  void update_divergence(const double* residual) noexcept;
  // True when the sample is an outlier (then `clean_` holds the residual
  // with the outlying outputs at their last good value).
  bool screen_outliers(const double* residual) noexcept;
  void update_detector(std::size_t j) noexcept;
  void locate(std::size_t j, std::size_t window, double scale) noexcept;
  void reset_output(std::size_t j) noexcept;
  void refresh_long_windows() noexcept;
  // A statistic T of window k of output j (of the focused detector when
  // `focused`): raise or clear, and locate.
  void react(std::size_t j, std::size_t k, double t, bool focused) noexcept;
  // The factor that turns s_W^T cov s_W into T_W for the full score.
  double full_scale(std::size_t j, std::size_t k) const noexcept;
  void test_focused(std::size_t j, std::size_t k) noexcept;

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
  NestedRls::Matrix scratch_;       // scratch for conditional RSS
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
  double lr_joint_raise_ = 0.0;
  double score_raise_ = 0.0;       // conditional score level naming a channel alone
  // Sequential detector and its per-output bookkeeping.
  SequentialDetector detector_;
  // Focused score: per input, the direction a gain mismatch of a model-
  // filtered channel takes after the AR reference has whitened the
  // residual: A(q) dG u = delta A(q) G_ji u, i.e. the lags of G_ji u
  // weighted by the nominal noise model's whitening polynomial [1, -g_N]
  // (e_0 when N or the plain-lag basis makes it unknown). nb x outputs.
  Eigen::MatrixXd focused_dir_;
  SequentialDetector focused_;
  Eigen::VectorXd focused_row_;                // m
  Eigen::MatrixXd focused_info_;               // m x m, per sample
  Eigen::LLT<Eigen::MatrixXd> focused_llt_ = factored_identity(0);
  Eigen::VectorXd focused_solve_;              // m
  std::vector<std::uint64_t> output_used_;  // samples used since the output's (re)start
  std::uint64_t burn_in_ = 0;               // used samples before the score is tested
  std::uint64_t score_start_ = 0;           // used samples before it accumulates
  std::vector<double> output_sum_w_;         // its sum of forgetting weights
  Eigen::VectorXd score_scratch_;            // m nb
  Eigen::MatrixXd locate_cov_;               // m nb x m nb, for a raise
  Eigen::VectorXd locate_v_;                 // m nb
  Eigen::MatrixXd locate_block_;             // nb x nb
  Eigen::VectorXd locate_x_;                 // nb
  Eigen::LLT<Eigen::MatrixXd> locate_llt_ = factored_identity(0);
  // Long windows' information refresh: one (output, window) every few
  // samples, round robin over every output (modelled or not, so a part of
  // the outputs refreshes exactly as the whole monitor does).
  Eigen::MatrixXd info_scratch_;               // m nb x m nb
  Eigen::LLT<Eigen::MatrixXd> info_llt_ = factored_identity(0);      // m nb (covariance form: S = P^-1)
  std::vector<std::uint64_t> refresh_last_;    // output_used_ at each pair's last refresh
  std::vector<Eigen::MatrixXd> info_last_;     // S at each pair's last refresh (m nb x m nb)
  std::vector<std::uint32_t> refresh_count_;   // refreshes since the output's (re)start
  std::uint64_t refresh_tick_ = 0;
  std::size_t refresh_cursor_ = 0;
  // Outlier screening per output: last good residual, mean absolute one-step
  // change (clipped), consecutive rejections; and the cleaned sample.
  std::vector<double> last_good_;
  std::vector<double> jump_scale_;
  std::vector<int> outlier_run_;
  std::vector<std::uint64_t> screened_;      // samples screened since the output's (re)start
  std::vector<double> clean_;
  // Outputs whose divergence ended this sample (with forgetting): restarted
  // by update_detector within the same update, so never saved.
  std::vector<std::uint8_t> recovered_;
  // Divergence detection per output: running mean and variance of d~ with a
  // short memory, and the quietest variance seen (the baseline).
  Eigen::VectorXd mean_fast_;
  Eigen::VectorXd var_fast_;
  Eigen::VectorXd var_baseline_;
  Eigen::VectorXd var_reference_;  // from the noise model; 0 = unknown
};

}  // namespace mpm
