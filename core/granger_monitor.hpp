// OVERVIEW
// Online Granger-causality monitor of model-plant mismatch (Chen, Xie & Su,
// Processes 2021, 9, 1976), one sample at a time, in fixed memory.
//
// For each output j the residual d~_j(k) is regressed on
//   [1, d~_j(k-1..k-na), x_1(k), ..., x_m(k)]
// where x_i holds nb regressors of input i (regressor_bank.hpp): the
// paper's plain lags u_i(k-1..k-nb) by default; with the nominal channel
// G_ji given, lags of G_ji u_i instead (model-filtered: still the past of
// u_i, but a gain mismatch dG = (k - 1) G_ji then lies in the span of two
// regressors instead of being smeared over nb lags and the residual's own
// AR part, so the test has far more power on the slow closed-loop data
// MPCs produce; channels the model says are zero keep plain lags); and
// optionally an orthonormal Laguerre basis with pole a (input_pole).
//
// The regressions are fitted by square-root-free (UD) recursive least
// squares with exponential forgetting, one shared update per output
// (nested_rls.hpp): the rows of [1, AR] are common to all of an output's
// models. From it come, every used sample (update_statistics):
//   * the AR-only residual variance Sigma1 and the full-model variance,
//   * the conditional Granger index of every input (all other inputs kept),
//     F_c(u_i -> d~_j) = ln(RSS without u_i / RSS full),
//   * from the pairwise models [1, AR, u_i], the paper's pairwise index
//     F(u_i -> d~_j) = ln(Sigma1 / Sigma2) and gamma(u_i -> d~_j), the
//     distance of their AR part from N^-1's,
//   * likelihood-ratio statistics LR = (n_eq - p) * F, chi-square with nb
//     dof (m nb for the joint test of all inputs) under "no causality",
//     where n_eq = (sum w)^2 / sum w^2 is the equivalent sample count of the
//     forgetting weights (= n for lambda = 1) and p the model's regressors.
// These feed the end-of-record test (record_verdict, monitor_front_end.hpp)
// at the per-channel false-alarm probability; they raise no live alarm.
//
// Live alarms (granger_alarms.cpp): a sequential detector per output
// (sequential_detector.hpp): the score test of all inputs against the
// AR-only model, accumulated over several memories at once, with
// thresholds derived from a stated false-alarm rate per unit time for the
// whole controller. Beside it, a focused score of m dof (per input, the
// lags of G_ji u_i weighted by the nominal noise model's whitening
// polynomial: the direction of a gain mismatch after the AR reference),
// sharing the rate half and half (Bonferroni): its threshold is far lower
// than the m nb-dof one's (measured on Wood-Berry G21 x 1.2: raised at
// 3000-4200 samples instead of 5000-12 000; the lag-0 column alone carried
// almost none of the signal, T ~ 5). The score accumulates from the
// factor's first sample and is tested after the burn-in. When an output is
// raised, the channel is named by the best evidence: the conditional score
// of each input given the others (from the raising window's score), or, if
// none stands out on its own, the paper's gamma rule (of the channels whose
// AR part matches N^-1, the one with the largest pairwise F).
//
// Robustness: a sample whose residual jumps by more than `outlier_limit`
// robust standard deviations of its recent one-step changes is skipped and
// counted (outlier_screen.hpp; the residual lags hold the previous value);
// an output whose statistics go non-finite starts again from its prior,
// counted. With forgetting, "diverging" holds while the residual's variance
// is far above its quietest level within the statistics' memory
// (divergence_watch.hpp), and the output starts again when it ends (its
// statistics hold the diverging samples).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Dense>

#include "core/divergence_watch.hpp"
#include "core/monitor_settings.hpp"
#include "core/nested_rls.hpp"
#include "core/outlier_screen.hpp"
#include "core/regressor_bank.hpp"
#include "core/sequential_detector.hpp"
#include "core/transfer_function.hpp"

namespace mpm {

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

  // Statistics as of the last update. The RSS-based ones (F, LR, gamma,
  // the variances) are computed from the factors when first read after a
  // used sample (refresh_statistics): the same numbers, but a sample nobody
  // reads costs no solve. So these readers write a cache: not for
  // concurrent use with each other or with update(). Real-time safe.
  const ChannelStats& channel(std::size_t output, std::size_t input) const noexcept {
    refresh_statistics(output);
    return channels_[output * n_inputs_ + input];
  }
  const LoopStats& loop(std::size_t output) const noexcept {
    refresh_statistics(output);
    return loops_[output];
  }
  // A channel's alarm flag alone, computing nothing: for readers of every
  // sample (AlarmEdges), so a sample whose statistics nobody reads costs no
  // solve.
  bool channel_alarm(std::size_t output, std::size_t input) const noexcept {
    return channels_[output * n_inputs_ + input].alarm;
  }
  const MonitorCounters& counters() const noexcept { return counters_; }

  // Equivalent sample count behind the current statistics.
  double effective_samples() const noexcept { return n_eq_; }
  // End-of-record test thresholds (chi-square quantiles at false_alarm).
  double raise_threshold() const noexcept { return lr_raise_; }
  double joint_raise_threshold() const noexcept { return lr_joint_raise_; }
  // The same thresholds at another level (false_alarm shared over a family
  // of tests, record_verdict); not for the hot path.
  double raise_threshold_at(double level) const noexcept;
  double joint_raise_threshold_at(double level) const noexcept;
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
  // Setup, before the first sample: the residuals start settled (the front
  // end skips no sample), so the first start waits only for the lags, not
  // for the model filters' memory (RegressorBank::start_settled()).
  void start_settled() noexcept { bank_.start_settled(); }

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
    for (std::size_t j = 0; j < n_outputs_; ++j) refresh_statistics(j);  // saved current
    bank_.visit_state(v);
    v(regressions_); v(channels_); v(loops_); v(counters_); v(in_gap_); v(used_since_reset_);
    v(sum_w_); v(sum_w2_); v(n_eq_);
    divergence_.visit_state(v);
    v(output_used_); v(output_sum_w_);
    screen_.visit_state(v);
    v(refresh_last_); v(refresh_count_); v(refresh_tick_); v(refresh_cursor_);
    detector_.visit_state(v);
    focused_.visit_state(v);
    for (Eigen::MatrixXd& m : info_last_) v(m);
  }

 private:
  // Per sample (granger_monitor.cpp).
  void absorb_sample(const double* residual) noexcept;
  void update_divergence(const double* residual) noexcept;
  void update_statistics() noexcept;
  // Output j's RSS-based statistics from its factor, if a used sample
  // changed the factor since they were last computed.
  void refresh_statistics(std::size_t j) const noexcept;
  void reset_output(std::size_t j) noexcept;
  // Live alarms (granger_alarms.cpp): the detectors' setup, their score of
  // output j this sample, the long windows' periodic refresh, and what a
  // statistic T of window k of output j (of the focused detector when
  // `focused`) does: raise or clear, and locate.
  void setup_detectors();
  void update_detector(std::size_t j) noexcept;
  void refresh_long_windows() noexcept;
  void test_focused(std::size_t j, std::size_t k) noexcept;
  void react(std::size_t j, std::size_t k, double t, bool focused) noexcept;
  void locate(std::size_t j, std::size_t window, double scale) noexcept;
  // The factor that turns s_W^T cov s_W into T_W for the full score.
  double full_scale(std::size_t j, std::size_t k) const noexcept;
  void reset_alarms() noexcept;
  void reset_alarms(std::size_t j) noexcept;

  MonitorSettings settings_;
  std::size_t n_inputs_;
  std::size_t n_outputs_;
  std::size_t first_output_ = 0;   // modelled outputs [first_output_, end_output_)
  std::size_t end_output_ = 0;
  std::size_t na_;
  std::size_t nb_;
  int warmup_;

  RegressorBank bank_;
  OutlierScreen screen_;
  DivergenceWatch divergence_;
  // Outputs whose divergence ended this sample (with forgetting): restarted
  // by update_detector within the same update, so never saved.
  std::vector<std::uint8_t> recovered_;

  // One per output: the full model [1, AR, u_1 .. u_m] and the pairwise
  // models [1, AR, u_i] in one shared update (nested_rls.hpp).
  std::vector<NestedRls> regressions_;
  mutable NestedRls::Matrix scratch_;       // scratch for conditional RSS
  // Scratch: one output's RSS ratios [joint, conditional (m), pairwise (m)]
  // and their logarithms, taken in one vectorised call.
  mutable Eigen::ArrayXd rss_ratios_;
  mutable Eigen::ArrayXd log_ratios_;

  std::vector<std::optional<Eigen::VectorXd>> n_inverse_ar_;
  // Mutable: their RSS-based fields are a cache (refresh_statistics).
  mutable std::vector<ChannelStats> channels_;
  mutable std::vector<LoopStats> loops_;
  // Per output: the factor changed since its statistics were computed.
  mutable std::vector<std::uint8_t> stale_;
  MonitorCounters counters_;
  bool in_gap_ = false;
  std::uint64_t used_since_reset_ = 0;

  double sum_w_ = 0.0;   // sum of forgetting weights
  double sum_w2_ = 0.0;  // sum of squared weights
  double n_eq_ = 0.0;
  double lr_raise_ = 0.0;
  double lr_joint_raise_ = 0.0;
  double score_raise_ = 0.0;       // conditional score level naming a channel alone

  // Live alarms (granger_alarms.cpp).
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
};

}  // namespace mpm
