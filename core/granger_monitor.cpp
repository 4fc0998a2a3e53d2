#include "core/granger_monitor.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "core/chi_square.hpp"

namespace mpm {
namespace {

constexpr double kRegularization = 1e-9;
// From this many inputs on, the full model's lower factor is kept in
// covariance form (BiermanRls) and the conditional statistics come from the
// Wald identity (O(nb^3) per input) instead of re-triangularisation
// (O(p^2 nb) per input); below it the covariance form's update and the
// pairwise factor it needs for the first input cost more than they save.
constexpr std::size_t kWaldMinInputs = 4;
// Divergence: the residual's short-memory variance exceeds this many times
// the matched-model variance (amplitude x 10), or, where that is unknown,
// 1000 times the quietest level it had: the loop is not stationary and a
// causality verdict on it would be meaningless (paper Sec. 4.2.4).
constexpr double kDivergenceOverReference = 100.0;
constexpr double kDivergenceRatio = 1e3;
constexpr double kFastMemory = 0.99;  // ~100-sample variance estimate
// Outlier screening: the mean absolute one-step change of the residual is
// learnt over this many samples before any is rejected, then followed with
// a ~200-sample memory (clipped at the limit, so an outlier cannot inflate
// it); this many consecutive rejections are a level shift, accepted.
constexpr std::uint64_t kOutlierLearn = 50;
// Long detector windows need their own information matrix (d x d per
// window and output): kept up to this many input regressors; beyond, only
// the first (exactly self-normalised) window runs.
constexpr std::size_t kLongWindowMaxDof = 100;
// One long window's information refreshed every this many samples.
constexpr std::uint64_t kRefreshEvery = 64;
// The first window of an output is looked at every this many samples
// (outputs staggered): its memory is thousands of samples, and one
// triangular solve per output and sample cost ~40 % of the 2x2 update.
constexpr std::uint64_t kFirstWindowEvery = 4;
// A long window is tested once its information has had this many refreshes:
// before, J_W is a few snapshots of S against a score summed over
// everything in between (measured: raises at the first refreshes).
constexpr std::uint32_t kMinRefreshes = 3;
constexpr double kJumpMemory = 0.995;
constexpr int kOutlierRunAccept = 5;
// Mean absolute value of a standard normal: mean |change| / this = sigma.
constexpr double kMeanAbsNormal = 0.7978845608;

bool finite_all(const double* v, std::size_t n) noexcept {
  for (std::size_t i = 0; i < n; ++i)
    if (!std::isfinite(v[i])) return false;
  return true;
}

}  // namespace

const std::vector<FieldRow<MonitorSettings>>& MonitorSettings::fields() {
  using S = MonitorSettings;
  static const std::vector<FieldRow<S>> rows = [] {
    std::vector<FieldRow<S>> r = {
        {"ar_order", [](S& s) { return &s.ar_order; }, {.min = 0, .max = 200, .whole = true}, "residual lags na"},
        {"input_order", [](S& s) { return &s.input_order; }, {.min = 1, .max = 200, .whole = true},
         "input lags nb (cover the longest dead time)"},
        {"forgetting", [](S& s) { return &s.forgetting; }, {.min = 0.9, .max = 1.0, .min_open = true},
         "RLS forgetting factor: memory of about 1/(1-forgetting) samples"},
        {"false_alarm", [](S& s) { return &s.false_alarm; }, {.min = 0.0, .max = 0.5, .min_open = true, .max_open = true},
         "level alpha of the end-of-record test, per channel and test"},
        {"outlier_limit", [](S& s) { return &s.outlier_limit; }, {.min = 3.0, .max = 1e6, .also = 0.0},
         "skip a residual jump beyond this many robust std devs (0 = never)"},
        {"warmup", [](S& s) { return &s.warmup; }, {.min = 0, .max = 1e9, .whole = true},
         "samples before any test (0 = 10 x regressors)"},
        {"gamma_lambda", [](S& s) { return &s.gamma_lambda; }, {.min = 0.0, .max = 1e9, .min_open = true},
         "the paper's lambda: gamma < lambda^2 locates"},
        {"input_pole", [](S& s) { return &s.input_pole; }, {.min = 0.0, .max = 0.99, .max_open = true},
         "Laguerre pole of the input basis (0 = plain lags)"},
    };
    for (auto& row : lift(DetectorSettings::fields(), &S::detector,
                          {"false_alarms_per_year", "sample_time", "crossing_constant", "detector_thresholds"}))
      r.push_back(std::move(row));
    return r;
  }();
  return rows;
}

std::vector<FieldError> MonitorSettings::errors() const {
  std::vector<FieldError> e = range_errors(fields(), *this);  // the detector's rows: below
  for (FieldError& f : detector.errors()) e.push_back(std::move(f));
  return e;
}

GrangerMonitor::GrangerMonitor(std::size_t n_inputs, std::size_t n_outputs, const MonitorSettings& settings,
                               std::vector<std::optional<std::vector<double>>> n_inverse_ar,
                               std::vector<double> reference_variance,
                               const std::vector<std::optional<DiscreteTf>>& channel_models,
                               OutputRange modelled)
    : settings_(settings), n_inputs_(n_inputs), n_outputs_(n_outputs) {
  if (const std::string err = settings.validate(); !err.empty()) throw std::invalid_argument(err);
  if (n_inputs == 0 || n_outputs == 0) throw std::invalid_argument("monitor needs at least one input and one output");
  if (modelled.first >= n_outputs) throw std::invalid_argument("modelled outputs: the range starts past the last output");
  first_output_ = modelled.first;
  end_output_ = modelled.first + std::min(modelled.count, n_outputs - modelled.first);
  if (!n_inverse_ar.empty() && n_inverse_ar.size() != n_outputs)
    throw std::invalid_argument("noise models: need one entry per output");
  na_ = static_cast<std::size_t>(settings.ar_order);
  nb_ = static_cast<std::size_t>(settings.input_order);
  const std::size_t p_full = n_regressors();
  input_lags_ = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(nb_), static_cast<Eigen::Index>(n_outputs * n_inputs));
  channel_filters_.resize(n_outputs * n_inputs);
  if (!channel_models.empty() && channel_models.size() != n_outputs * n_inputs)
    throw std::invalid_argument("channel models: need n_outputs * n_inputs entries");
  for (std::size_t c = 0; c < channel_models.size(); ++c) {
    if (!channel_models[c] || channel_models[c]->is_zero()) continue;
    DiscreteTf tf = *channel_models[c];
    tf.normalise();
    std::size_t lead = 0;  // leading zero coefficients are delay
    while (lead + 1 < tf.num.size() && tf.num[lead] == 0.0) ++lead;
    tf.num.erase(tf.num.begin(), tf.num.begin() + static_cast<long>(lead));
    tf.delay += static_cast<int>(lead);
    if (tf.delay > 0) --tf.delay;  // stepping with u(k) gives G u at k+1
    if (!tf.is_stable()) continue;  // an integrating model channel would drift: plain lags
    channel_filters_[c].emplace(tf);
    // The filter starts at rest after a (re)start: wait for its memory too.
    double slowest = 0.0;
    for (double mag : root_magnitudes(tf.den)) slowest = std::max(slowest, mag);
    int settle = tf.delay + static_cast<int>(tf.num.size());
    if (slowest > 0.0) settle += static_cast<int>(std::ceil(std::log(0.01) / std::log(slowest)));
    filter_settle_ = std::max(filter_settle_, std::min(settle, 2000));
  }
  // After a start or a gap, the residual lags need na samples; the Laguerre
  // states need nb samples and then until the pre-gap memory (zeroed) has
  // decayed to 1 %; model filters likewise.
  lags_needed_ = static_cast<int>(std::max(na_, nb_)) + filter_settle_;
  if (settings.input_pole > 0.0)
    lags_needed_ = std::max(lags_needed_, static_cast<int>(nb_) + static_cast<int>(std::ceil(std::log(0.01) / std::log(settings.input_pole))));
  warmup_ = settings.warmup > 0 ? settings.warmup : static_cast<int>(10 * p_full);

  // Factors only for the modelled outputs (the others stay empty).
  regressions_.resize(n_outputs);
  for (std::size_t j = first_output_; j < end_output_; ++j) {
    regressions_[j] = NestedRls(1 + na_, n_inputs, nb_, settings.forgetting, kRegularization, n_inputs >= kWaldMinInputs);
  }
  residual_lags_ = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(na_), static_cast<Eigen::Index>(n_outputs));
  input_ref_ = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n_inputs));
  pair_coef_.resize(static_cast<Eigen::Index>(1 + na_));
  const auto lower = static_cast<Eigen::Index>(n_inputs * nb_ + 1);
  scratch_.resize(lower, lower);
  rss_ratios_ = Eigen::ArrayXd::Ones(static_cast<Eigen::Index>(1 + 2 * n_inputs));
  log_ratios_ = Eigen::ArrayXd::Zero(static_cast<Eigen::Index>(1 + 2 * n_inputs));

  n_inverse_ar_.resize(n_outputs);
  for (std::size_t j = 0; j < n_inverse_ar.size(); ++j) {
    if (!n_inverse_ar[j]) continue;
    if (n_inverse_ar[j]->size() < na_)
      throw std::invalid_argument("noise model AR coefficients shorter than ar_order");
    n_inverse_ar_[j] = Eigen::Map<const Eigen::VectorXd>(n_inverse_ar[j]->data(), static_cast<Eigen::Index>(na_));
  }
  channels_.assign(n_outputs * n_inputs, ChannelStats{});
  loops_.assign(n_outputs, LoopStats{});
  mean_fast_ = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n_outputs));
  var_fast_ = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n_outputs));
  var_baseline_ = Eigen::VectorXd::Constant(static_cast<Eigen::Index>(n_outputs), INFINITY);
  if (!reference_variance.empty() && reference_variance.size() != n_outputs)
    throw std::invalid_argument("reference variance: need one entry per output");
  var_reference_ = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n_outputs));
  for (std::size_t j = 0; j < reference_variance.size(); ++j)
    if (std::isfinite(reference_variance[j]) && reference_variance[j] > 0.0)
      var_reference_[static_cast<Eigen::Index>(j)] = reference_variance[j];

  const double dof = static_cast<double>(nb_);
  lr_raise_ = chi_square_quantile_upper(settings.false_alarm, dof);
  lr_joint_raise_ = chi_square_quantile_upper(settings.false_alarm, dof * static_cast<double>(n_inputs));
  score_raise_ = lr_raise_;
  // The stated rate is the whole controller's: shared by all its outputs,
  // also when this monitor models only a part of them.
  const std::size_t d = n_inputs * nb_;
  // The shortest memory is the one whose squared weights equal the factor's
  // (rho^2 = lambda): there S is exactly the score's conditional variance,
  // however the inputs moved, so T is chi-square even across setpoint steps
  // (measured: shorter windows normalised by S raise on every step).
  DetectorSettings detector = settings.detector;
  if (d > kLongWindowMaxDof) {
    detector.windows = 1;
    if (detector.thresholds.size() > 1) detector.thresholds.erase(detector.thresholds.begin() + 1, detector.thresholds.end());
  }
  if (detector.first_window == 0.0)
    detector.first_window = settings.forgetting < 1.0 ? std::min(2.0 / (1.0 - settings.forgetting), 1e6) : 2000.0;
  // Long windows are looked at when their information is refreshed: one
  // (output, window) every kRefreshEvery samples, round robin.
  const double long_period = static_cast<double>(kRefreshEvery * n_outputs * static_cast<std::size_t>(std::max(detector.windows - 1, 1)));
  // Two statistics share the stated rate (Bonferroni): the full score (m nb
  // dof) and the focused one (m dof), whose threshold at the same rate is
  // far lower, so a mismatch in the direction it tests (a gain, mostly
  // also a time constant or dead time of a model-filtered channel) crosses
  // it with a fraction of the samples.
  detector.false_alarms_per_year *= 0.5;
  detector_ = SequentialDetector(n_outputs, d, detector, n_outputs, long_period,
                                 static_cast<double>(kFirstWindowEvery));
  DetectorSettings focused = detector;
  focused.thresholds.clear();  // `mpm calibrate` fits the full score's
  // The focused first window is looked at with every refresh of its output.
  focused_ = SequentialDetector(n_outputs, n_inputs, focused, n_outputs, long_period,
                                static_cast<double>(kRefreshEvery * n_outputs));
  focused_dir_ = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(nb_), static_cast<Eigen::Index>(n_outputs));
  for (std::size_t j = 0; j < n_outputs; ++j) {
    auto v = focused_dir_.col(static_cast<Eigen::Index>(j));
    v[0] = 1.0;
    if (settings.input_pole == 0.0 && n_inverse_ar_[j])
      for (std::size_t l = 1; l < nb_ && l <= na_; ++l) v[static_cast<Eigen::Index>(l)] = -(*n_inverse_ar_[j])[static_cast<Eigen::Index>(l - 1)];
    v.normalize();
  }
  focused_row_ = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n_inputs));
  focused_info_ = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(n_inputs), static_cast<Eigen::Index>(n_inputs));
  focused_llt_ = factored_identity(static_cast<Eigen::Index>(n_inputs));
  focused_solve_ = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n_inputs));
  output_used_.assign(n_outputs, 0);
  output_sum_w_.assign(n_outputs, 0.0);
  score_scratch_ = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(d));
  locate_cov_ = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(d), static_cast<Eigen::Index>(d));
  locate_v_ = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(d));
  locate_block_ = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(nb_), static_cast<Eigen::Index>(nb_));
  locate_x_ = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(nb_));
  locate_llt_ = factored_identity(static_cast<Eigen::Index>(nb_));
  if (detector_.windows() > 1) {
    info_scratch_ = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(d), static_cast<Eigen::Index>(d));
    info_llt_ = factored_identity(static_cast<Eigen::Index>(d));
    info_last_.assign(n_outputs * detector_.windows(), Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(d), static_cast<Eigen::Index>(d)));
  }
  // The score starts once the factor's memory is full: before, the AR
  // reference and S are estimates from a few hundred samples and the score
  // is heavy tailed (measured: raises ~100 samples after the warm-up).
  burn_in_ = std::max<std::uint64_t>(static_cast<std::uint64_t>(warmup_),
                                     settings.forgetting < 1.0 ? static_cast<std::uint64_t>(std::min(1.0 / (1.0 - settings.forgetting), 1e6)) : 0);
  // The score accumulates from the factor's first sample, so the first
  // window's weights (rho_0^2 = lambda) are those of S, its normaliser,
  // from the start: started at the burn-in instead, its few hundred recent
  // samples were normalised by S of the whole memory and crossed whenever
  // the excitation had moved (measured: raises clustered right after the
  // burn-in on all three plants).
  score_start_ = 1;
  refresh_last_.assign(n_outputs * detector_.windows(), score_start_);
  refresh_count_.assign(n_outputs * detector_.windows(), 0);
  last_good_.assign(n_outputs, 0.0);
  jump_scale_.assign(n_outputs, 0.0);
  outlier_run_.assign(n_outputs, 0);
  screened_.assign(n_outputs, 0);
  clean_.assign(n_outputs, 0.0);
  recovered_.assign(n_outputs, 0);
  reset();
}

void GrangerMonitor::reset() noexcept {
  for (std::size_t j = first_output_; j < end_output_; ++j) regressions_[j].reset();
  residual_lags_.setZero();
  input_lags_.setZero();
  for (auto& f : channel_filters_)
    if (f) f->reset(0.0);
  lags_filled_ = 0;
  in_gap_ = false;
  sum_w_ = sum_w2_ = n_eq_ = 0.0;
  std::fill(channels_.begin(), channels_.end(), ChannelStats{});
  std::fill(loops_.begin(), loops_.end(), LoopStats{});
  mean_fast_.setZero();
  var_fast_.setZero();
  var_baseline_.setConstant(INFINITY);
  for (auto& c : channels_) c.gamma = NAN;
  used_since_reset_ = 0;
  detector_.reset();
  focused_.reset();
  std::fill(output_used_.begin(), output_used_.end(), 0);
  std::fill(output_sum_w_.begin(), output_sum_w_.end(), 0.0);
  std::fill(jump_scale_.begin(), jump_scale_.end(), 0.0);
  std::fill(outlier_run_.begin(), outlier_run_.end(), 0);
  std::fill(screened_.begin(), screened_.end(), 0);
  std::fill(refresh_last_.begin(), refresh_last_.end(), score_start_);
  for (Eigen::MatrixXd& m : info_last_) m.setZero();
  std::fill(refresh_count_.begin(), refresh_count_.end(), 0);
  refresh_tick_ = 0;
  refresh_cursor_ = 0;
}

void GrangerMonitor::reset_output(std::size_t j) noexcept {
  // Non-finite statistics (an input of 1e300, a factor that overflowed):
  // this output starts again from its prior; the others keep theirs.
  const auto jj = static_cast<Eigen::Index>(j);
  regressions_[j].reset();
  residual_lags_.col(jj).setZero();
  detector_.reset_output(j);
  focused_.reset_output(j);
  output_used_[j] = 0;
  output_sum_w_[j] = 0.0;
  jump_scale_[j] = 0.0;
  outlier_run_[j] = 0;
  screened_[j] = 0;
  for (std::size_t k = 0; k < detector_.windows(); ++k) {
    refresh_last_[j * detector_.windows() + k] = score_start_;
    if (!info_last_.empty()) info_last_[j * detector_.windows() + k].setZero();
    refresh_count_[j * detector_.windows() + k] = 0;
  }
  mean_fast_[jj] = 0.0;
  var_fast_[jj] = 0.0;
  var_baseline_[jj] = INFINITY;
  loops_[j] = LoopStats{};
  for (std::size_t i = 0; i < n_inputs_; ++i) {
    channels_[j * n_inputs_ + i] = ChannelStats{};
    channels_[j * n_inputs_ + i].gamma = NAN;
  }
  ++counters_.resets;
}

bool GrangerMonitor::ready() const noexcept { return used_since_reset_ >= static_cast<std::uint64_t>(warmup_); }

double GrangerMonitor::p_value(double lr) const noexcept {
  return chi_square_survival(lr, static_cast<double>(nb_));
}

double GrangerMonitor::joint_p_value(double lr) const noexcept {
  return chi_square_survival(lr, static_cast<double>(nb_ * n_inputs_));
}

SampleStatus GrangerMonitor::update(const double* u, const double* residual) noexcept {
  ++counters_.samples;
  if (!finite_all(u, n_inputs_) || !finite_all(residual, n_outputs_)) {
    // Skip the sample; the lag windows straddling it are invalid, so the
    // regression restarts filling its lags after the gap.
    ++counters_.missing;
    if (!in_gap_) ++counters_.gaps;
    in_gap_ = true;
    lags_filled_ = 0;
    input_lags_.setZero();
    for (auto& f : channel_filters_)
      if (f) f->reset(0.0);
    return SampleStatus::kMissing;
  }
  in_gap_ = false;
  if (lags_filled_ == 0) {  // (re)start: the basis starts at rest at this level
    for (std::size_t i = 0; i < n_inputs_; ++i) input_ref_[static_cast<Eigen::Index>(i)] = u[i];
  }
  SampleStatus status = SampleStatus::kWarmingUp;
  if (lags_filled_ >= lags_needed_) {
    if (screen_outliers(residual)) {
      ++counters_.outliers;
      push_lags(u, clean_.data());
      return SampleStatus::kOutlier;
    }
    absorb_sample(residual);
    ++counters_.used;
    ++used_since_reset_;
    update_divergence(residual);
    update_statistics();
    status = SampleStatus::kUsed;
  }
  push_lags(u, residual);
  return status;
}

bool GrangerMonitor::screen_outliers(const double* residual) noexcept {
  if (settings_.outlier_limit == 0.0) return false;
  bool outlier = false;
  // Every output, modelled or not: a monitor of a part of the outputs skips
  // exactly the samples the whole monitor skips.
  for (std::size_t j = 0; j < n_outputs_; ++j) {
    clean_[j] = residual[j];
    const double jump = std::abs(residual[j] - last_good_[j]);
    const std::uint64_t n = screened_[j]++;
    double& scale = jump_scale_[j];  // mean |one-step change|
    if (n == 0) {  // first sample after a (re)start: nothing to compare with
      last_good_[j] = residual[j];
      continue;
    }
    if (n < kOutlierLearn) {  // learning the scale: plain running mean
      scale += (jump - scale) / static_cast<double>(n);
      last_good_[j] = residual[j];
      continue;
    }
    const double limit = settings_.outlier_limit * scale / kMeanAbsNormal;
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
    for (std::size_t j = 0; j < n_outputs_; ++j)
      if (clean_[j] == residual[j] && outlier_run_[j] == 0) last_good_[j] = residual[j];
  }
  return outlier;
}

void GrangerMonitor::absorb_sample(const double* residual) noexcept {
  const double lambda = settings_.forgetting;
  sum_w_ = lambda * sum_w_ + 1.0;
  sum_w2_ = lambda * lambda * sum_w2_ + 1.0;
  n_eq_ = sum_w_ * sum_w_ / sum_w2_;

  // Regressor rows written straight into each output's staged row:
  // [1, AR lags of d~_j, lags of u_1, ..., u_m, target d~_j(k)].
  const std::size_t inputs = n_inputs_ * nb_;
  for (std::size_t j = first_output_; j < end_output_; ++j) {
    const double* ar = residual_lags_.col(static_cast<Eigen::Index>(j)).data();
    const double* lags = input_lags_.col(static_cast<Eigen::Index>(j * n_inputs_)).data();  // nb per input
    double* f = regressions_[j].staged_row();
    f[0] = 1.0;
    std::copy(ar, ar + na_, f + 1);
    std::copy(lags, lags + inputs, f + 1 + na_);
    f[1 + na_ + inputs] = residual[j];
  }
  NestedRls::update_staged(regressions_.data() + first_output_, end_output_ - first_output_);
}

void GrangerMonitor::push_lags(const double* u, const double* residual) noexcept {
  // Newest first: shift each output's column down by one, time k on top.
  if (na_ > 0)
    for (std::size_t j = 0; j < n_outputs_; ++j) {
      double* lags = residual_lags_.col(static_cast<Eigen::Index>(j)).data();
      std::copy_backward(lags, lags + na_ - 1, lags + na_);
      lags[0] = residual[j];
    }
  // Laguerre network, one column per input: x_1 <- a x_1 + sqrt(1-a^2) u(k),
  // x_r <- a x_r + x_{r-1}(old) - a x_{r-1}(new). With a = 0: a shift register.
  const double a = settings_.input_pole;
  const double gain = std::sqrt(1.0 - a * a);
  for (std::size_t c = first_output_ * n_inputs_; c < end_output_ * n_inputs_; ++c) {
    const std::size_t i = c % n_inputs_;
    double source = u[i] - input_ref_[static_cast<Eigen::Index>(i)];
    if (channel_filters_[c]) source = channel_filters_[c]->step(source);
    double* x = input_lags_.col(static_cast<Eigen::Index>(c)).data();
    if (a == 0.0) {  // plain lags (the default): a shift register
      std::copy_backward(x, x + nb_ - 1, x + nb_);
      x[0] = source;
      continue;
    }
    double prev_old = x[0];
    x[0] = a * x[0] + gain * source;
    for (std::size_t r = 1; r < nb_; ++r) {
      const double old = x[r];
      x[r] = a * x[r] + prev_old - a * x[r - 1];
      prev_old = old;
    }
  }
  if (lags_filled_ < 1 << 30) ++lags_filled_;
}

void GrangerMonitor::update_divergence(const double* residual) noexcept {
  for (std::size_t j = first_output_; j < end_output_; ++j) {
    const auto jj = static_cast<Eigen::Index>(j);
    // Residuals carry the outputs' operating-point offset: start the running
    // mean there, not at zero.
    if (output_used_[j] == 0) mean_fast_[jj] = residual[j];
    const double dev = residual[j] - mean_fast_[jj];
    mean_fast_[jj] += (1.0 - kFastMemory) * dev;
    var_fast_[jj] = kFastMemory * var_fast_[jj] + (1.0 - kFastMemory) * dev * dev;
    // With forgetting, the quietest level is that of the statistics' own
    // memory: it rises by 1/lambda per sample, so a level from before that
    // memory stops counting. The soak found the flag sticky: one stretch of
    // values x 1e8 or x 1e-8 left the live monitor "diverging", and so
    // without verdicts, for good. With lambda = 1 (a whole record) the
    // statistics keep the diverging samples, and the flag stays.
    const bool forgets = settings_.forgetting < 1.0;
    if (forgets) var_baseline_[jj] /= settings_.forgetting;
    // The short-memory estimate is settled after a few hundred samples.
    if (output_used_[j] > 300) var_baseline_[jj] = std::min(var_baseline_[jj], var_fast_[jj]);
    const bool diverging = var_fast_[jj] > kDivergenceRatio * var_baseline_[jj] ||
                           (var_reference_[jj] > 0.0 && output_used_[j] > 100 &&
                            var_fast_[jj] > kDivergenceOverReference * var_reference_[jj]);
    // Back from diverging, the statistics still hold those samples (x 1e8
    // of the rest, measured: false raises with scores of 1e8 thousands of
    // samples later): the output starts again (update_detector).
    if (forgets && loops_[j].diverging && !diverging) recovered_[j] = 1;
    loops_[j].diverging = diverging || (!forgets && loops_[j].diverging);
  }
}

void GrangerMonitor::update_statistics() noexcept {
  const std::size_t p_full = n_regressors();
  const std::size_t p_pair = 1 + na_ + nb_;
  const double scale_full = std::max(n_eq_ - static_cast<double>(p_full), 1.0);
  const double scale_pair = std::max(n_eq_ - static_cast<double>(p_pair), 1.0);
  for (std::size_t j = first_output_; j < end_output_; ++j) {
    const NestedRls& reg = regressions_[j];
    LoopStats& loop = loops_[j];
    const double rss_full = reg.rss_full();
    const double rss_ar = reg.rss_prefix_only();
    loop.sigma1 = rss_ar / sum_w_;
    loop.sigma_full = rss_full / sum_w_;
    loop.residual_variance = reg.rss_head(1) / sum_w_;
    // Every F of this output is the log of an RSS ratio: the ratios first,
    // then one vectorised log for all of them (a scalar log each costs as
    // much as a rotation).
    const auto m = static_cast<Eigen::Index>(n_inputs_);
    rss_ratios_[0] = rss_ar / rss_full;
    for (std::size_t i = 0; i < n_inputs_; ++i) {
      const auto ii = static_cast<Eigen::Index>(i);
      rss_ratios_[1 + ii] = reg.rss_without_block(i, scratch_) / rss_full;
      rss_ratios_[1 + m + ii] = reg.rss_pair_prefix_only(i) / reg.rss_pair(i);
    }
    log_ratios_ = rss_ratios_.log();
    loop.lr_joint = scale_full * log_ratios_[0];
    // The AR parts of every pairwise model, for gamma, in one solve.
    const Eigen::MatrixXd* pair_prefix = n_inverse_ar_[j] ? &reg.solve_pairs_prefix() : nullptr;
    for (std::size_t i = 0; i < n_inputs_; ++i) {
      const auto ii = static_cast<Eigen::Index>(i);
      ChannelStats& c = channels_[j * n_inputs_ + i];
      c.f_conditional = log_ratios_[1 + ii];
      c.lr_conditional = scale_full * c.f_conditional;
      c.f_pairwise = log_ratios_[1 + m + ii];
      c.lr_pairwise = scale_pair * c.f_pairwise;

      if (n_inverse_ar_[j]) {
        // gamma = ||g_hat - g_N||^2 / ||[1, -g_N]||^2: the distance between
        // the fitted AR part and that of N^-1, relative to the whole N^-1
        // polynomial (leading 1 included), so a white N (g_N = 0) is fine.
        const auto& g_n = *n_inverse_ar_[j];
        const auto g_hat = pair_prefix->col(static_cast<Eigen::Index>(i)).segment(1, static_cast<Eigen::Index>(na_));
        const double dist = (g_hat - g_n).squaredNorm();
        c.gamma = dist / (1.0 + g_n.squaredNorm());
      }
      if (loop.diverging) c.alarm = false;  // no verdict on a diverging loop
    }
    update_detector(j);
  }
  refresh_long_windows();
}

void GrangerMonitor::refresh_long_windows() noexcept {
  const std::size_t kw = detector_.windows();
  if (kw < 2 || ++refresh_tick_ < kRefreshEvery) return;
  refresh_tick_ = 0;
  const std::size_t pairs = n_outputs_ * (kw - 1);
  const std::size_t c = refresh_cursor_;
  refresh_cursor_ = (refresh_cursor_ + 1) % pairs;
  const std::size_t j = c / (kw - 1), k = 1 + c % (kw - 1);
  if (j < first_output_ || j >= end_output_ || output_used_[j] <= score_start_) return;
  const NestedRls& reg = regressions_[j];
  const std::size_t d = n_inputs_ * nb_;
  if (reg.covariance_form()) {  // S = P^-1
    reg.inputs_covariance(locate_cov_.data(), d);
    info_llt_.compute(locate_cov_);
    info_scratch_.setIdentity();
    info_llt_.solveInPlace(info_scratch_);
  } else {
    reg.inputs_information(info_scratch_.data(), d);
  }
  std::uint64_t& last = refresh_last_[j * kw + k];
  const double gap = static_cast<double>(output_used_[j] - last);
  last = output_used_[j];
  // The information the gap's samples brought, per sample: the increment
  // of S over the gap, S_now - lambda^gap S_then (the factor forgets by
  // lambda per used sample), over the weight S gives those samples. Not
  // the snapshot S / n: after a loss of excitation (held inputs) S / n
  // lags the information the score gathers by S's memory 1 / (1 - lambda)
  // (~ (1 - lambda^t) of it t samples after the inputs move again), so a
  // long window credited each gap with the snapshot was normalised by too
  // little information and crossed (the soak: 9 of 100 frozen stretches
  // raised 80..280 samples after the inputs moved; `GrangerMonitor.
  // FrozenInputsMovingAgainRaiseNothing`). In steady state both are the
  // same. The increment is positive semidefinite in exact arithmetic (a
  // Schur complement is superadditive); when rounding makes it indefinite
  // (S falling by 1e16 after a loud stretch) the snapshot is used.
  Eigen::MatrixXd& then = info_last_[j * kw + k];
  const double lambda = settings_.forgetting;
  const double decay = std::pow(lambda, gap);
  const double spread = lambda < 1.0 ? (1.0 - decay) / (1.0 - lambda) : gap;
  locate_cov_ = info_scratch_;
  locate_cov_.noalias() -= decay * then;
  then = info_scratch_;
  info_llt_.compute(locate_cov_);
  if (info_llt_.info() == Eigen::Success && spread > 0.0) info_scratch_ = locate_cov_ / spread;
  else info_scratch_ /= output_sum_w_[j];
  detector_.refresh_information(j, k, info_scratch_, gap);
  // The focused information per sample: v^T S_ab v for every pair of
  // inputs (locate_x_ as scratch: no allocation), of the gap's increment
  // for window k and of the snapshot S / n for the first window (J_0 =
  // V_0 S / n: its weights are the factor's).
  const auto nb = static_cast<Eigen::Index>(nb_);
  const auto dir = focused_dir_.col(static_cast<Eigen::Index>(j));
  const auto project = [&](const Eigen::MatrixXd& info, double scale) {
    for (std::size_t a = 0; a < n_inputs_; ++a)
      for (std::size_t b = 0; b < n_inputs_; ++b) {
        locate_x_.noalias() = info.block(static_cast<Eigen::Index>(a) * nb, static_cast<Eigen::Index>(b) * nb, nb, nb) * dir;
        focused_info_(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b)) = scale * dir.dot(locate_x_);
      }
  };
  project(info_scratch_, 1.0);
  focused_.refresh_information(j, k, focused_info_, gap);
  project(then, 1.0 / output_sum_w_[j]);
  if (output_used_[j] >= burn_in_ && !loops_[j].diverging) test_focused(j, 0);
  std::uint32_t& count = refresh_count_[j * kw + k];
  if (count < kMinRefreshes) ++count;
  // ... and once its memory 2 V is past the shorter window's: before, it
  // holds the same samples as that window with a coarser J_W (snapshots of
  // S every few hundred samples), and its tests only add false alarms
  // (measured: raises clustered at the start on the quadruple tank).
  if (count < kMinRefreshes || output_used_[j] < burn_in_ || 2.0 * detector_.weight(j, k) < detector_.window(k - 1) ||
      !detector_.has_information(j, k) || loops_[j].diverging)
    return;
  // T = s^T J^-1 s / sigma_W^2, both of the window's own memory.
  const double var = detector_.variance(j, k);
  const double t = detector_.normalised_quadratic(j, k) / var;
  if (std::isfinite(t)) react(j, k, t, false);
  test_focused(j, k);
}

void GrangerMonitor::test_focused(std::size_t j, std::size_t k) noexcept {
  double t = 0.0;
  if (k == 0) {
    // J_0 = V_0 S_sub / n: the first window's weights are the factor's.
    focused_llt_.compute(focused_info_);
    if (focused_llt_.info() != Eigen::Success) return;
    focused_solve_ = Eigen::Map<const Eigen::VectorXd>(focused_.sum(j, 0), focused_solve_.size());
    focused_llt_.matrixL().solveInPlace(focused_solve_);
    t = focused_solve_.squaredNorm() / (focused_.variance(j, 0) * focused_.weight(j, 0));
  } else {
    if (!focused_.has_information(j, k)) return;
    t = focused_.normalised_quadratic(j, k) / focused_.variance(j, k);
  }
  if (std::isfinite(t)) react(j, k, t, true);
}

double GrangerMonitor::full_scale(std::size_t j, std::size_t k) const noexcept {
  if (k > 0) return 1.0 / detector_.variance(j, k);
  const double n = output_sum_w_[j];
  return n * n / (regressions_[j].rss_prefix_only() * detector_.weight(j, 0));
}

void GrangerMonitor::update_detector(std::size_t j) noexcept {
  NestedRls& reg = regressions_[j];
  LoopStats& loop = loops_[j];
  const double lambda = settings_.forgetting;
  ++output_used_[j];
  output_sum_w_[j] = lambda * output_sum_w_[j] + 1.0;
  const double rss_ar = reg.rss_prefix_only();
  if (!std::isfinite(rss_ar) || !std::isfinite(reg.rss_full()) || recovered_[j]) {
    recovered_[j] = 0;
    reset_output(j);
    return;
  }
  if (output_used_[j] < score_start_) return;
  // Score of the inputs' block against the AR-only model, this sample.
  const std::size_t d = n_inputs_ * nb_;
  const double* row = reg.apriori_row();
  const double w = reg.apriori_weight();
  detector_.accumulate(j, row, w * row[d], w * row[d] * row[d]);
  const auto nb = static_cast<Eigen::Index>(nb_);
  const auto dir = focused_dir_.col(static_cast<Eigen::Index>(j));
  for (std::size_t i = 0; i < n_inputs_; ++i)
    focused_row_[static_cast<Eigen::Index>(i)] = dir.dot(Eigen::Map<const Eigen::VectorXd>(row + i * nb_, nb));
  focused_.accumulate(j, focused_row_.data(), w * row[d], w * row[d] * row[d]);
  if (output_used_[j] < burn_in_) return;
  if (loop.diverging) {  // no verdict on a diverging loop
    loop.alarm = false;
    return;
  }
  // The first window every sample (rho^2 = lambda: S is the score's own
  // variance); the long ones when refresh_long_windows() renews them.
  if ((output_used_[j] + j) % kFirstWindowEvery != 0) return;
  const double n = output_sum_w_[j];
  // Normalised by the weight the window has accumulated (not its stationary
  // 1 / (1 - rho^2)): chi-square from the first sample of the score.
  const double scale = n * n / (rss_ar * detector_.weight(j, 0));
  const double t = scale * reg.information_quadratic(detector_.sum(j, 0), score_scratch_.data());
  if (!std::isfinite(t)) {
    reset_output(j);
    return;
  }
  react(j, 0, t, false);
}

void GrangerMonitor::react(std::size_t j, std::size_t k, double t, bool focused) noexcept {
  LoopStats& loop = loops_[j];
  SequentialDetector& det = focused ? focused_ : detector_;
  const SequentialDetector& other = focused ? detector_ : focused_;
  switch (det.test(j, k, t)) {
    case DetectorEvent::kRaised:
      if (other.raised(j)) break;  // the output is raised already
      ++counters_.raises;
      loop.alarm = true;
      loop.score = t;
      loop.score_threshold = det.threshold_now(j, k);
      loop.score_window = det.window(k);
      // The channel from the full score of the raising window (its
      // covariance is known for the first window and refreshed ones).
      locate(j, k > 0 && !detector_.has_information(j, k) ? 0 : k,
             full_scale(j, k > 0 && !detector_.has_information(j, k) ? 0 : k));
      break;
    case DetectorEvent::kCleared:
      if (other.raised(j)) break;  // still raised by the other statistic
      loop.alarm = false;
      for (std::size_t i = 0; i < n_inputs_; ++i) {
        channels_[j * n_inputs_ + i].alarm = false;
        channels_[j * n_inputs_ + i].located_by_gamma = false;
      }
      break;
    case DetectorEvent::kNone:
      break;
  }
}

void GrangerMonitor::locate(std::size_t j, std::size_t window, double scale) noexcept {
  // The conditional score of block i given the others: with P = S^-1 and
  // v = P s, s^T S^-1 s - s_-i^T S_-i^-1 s_-i = v_i^T [P]_ii^-1 v_i (Schur).
  // O((m nb)^3), on a raise only; everything preallocated.
  const std::size_t d = n_inputs_ * nb_;
  const auto dd = static_cast<Eigen::Index>(d);
  const auto nb = static_cast<Eigen::Index>(nb_);
  // The window's own variance: S^-1 for the first window, J_W^-1 for the
  // others (`scale` turns s^T cov s into its T).
  if (window == 0) regressions_[j].inputs_covariance(locate_cov_.data(), d);
  else detector_.information_inverse(j, window, locate_cov_);
  const Eigen::Map<const Eigen::VectorXd> s(detector_.sum(j, window), dd);
  locate_v_.noalias() = locate_cov_ * s;
  std::size_t best = 0;
  for (std::size_t i = 0; i < n_inputs_; ++i) {
    const auto b0 = static_cast<Eigen::Index>(i) * nb;
    locate_block_ = locate_cov_.block(b0, b0, nb, nb);
    locate_llt_.compute(locate_block_);
    locate_x_ = locate_v_.segment(b0, nb);
    locate_llt_.solveInPlace(locate_x_);
    ChannelStats& c = channels_[j * n_inputs_ + i];
    c.score_conditional = scale * locate_v_.segment(b0, nb).dot(locate_x_);
    if (!std::isfinite(c.score_conditional)) c.score_conditional = 0.0;
    c.alarm = false;
    c.located_by_gamma = false;
    if (c.score_conditional > channels_[j * n_inputs_ + best].score_conditional) best = i;
  }
  // No input stands out on its own (collinear inputs): the paper's rule,
  // among the channels whose AR part matches N^-1 the largest pairwise F.
  if (channels_[j * n_inputs_ + best].score_conditional < score_raise_) {
    const double limit = settings_.gamma_lambda * settings_.gamma_lambda;
    std::size_t by_gamma = n_inputs_;
    for (std::size_t i = 0; i < n_inputs_; ++i) {
      const ChannelStats& c = channels_[j * n_inputs_ + i];
      if (c.gamma < limit && (by_gamma == n_inputs_ || c.f_pairwise > channels_[j * n_inputs_ + by_gamma].f_pairwise))
        by_gamma = i;
    }
    if (by_gamma < n_inputs_) {
      channels_[j * n_inputs_ + by_gamma].alarm = true;
      channels_[j * n_inputs_ + by_gamma].located_by_gamma = true;
      return;
    }
  }
  channels_[j * n_inputs_ + best].alarm = true;
}

void GrangerMonitor::adopt_outputs(const GrangerMonitor& part) {
  if (part.n_inputs_ != n_inputs_ || part.n_outputs_ != n_outputs_ || part.na_ != na_ || part.nb_ != nb_ ||
      part.lags_needed_ != lags_needed_ || part.warmup_ != warmup_)
    throw std::invalid_argument("adopt_outputs: the monitors differ in shape or settings");
  if (part.first_output_ < first_output_ || part.end_output_ > end_output_)
    throw std::invalid_argument("adopt_outputs: the part models outputs this monitor does not");
  for (std::size_t j = part.first_output_; j < part.end_output_; ++j) {
    const auto jj = static_cast<Eigen::Index>(j);
    regressions_[j] = part.regressions_[j];
    residual_lags_.col(jj) = part.residual_lags_.col(jj);
    for (std::size_t i = 0; i < n_inputs_; ++i) {
      const std::size_t c = j * n_inputs_ + i;
      input_lags_.col(static_cast<Eigen::Index>(c)) = part.input_lags_.col(static_cast<Eigen::Index>(c));
      channel_filters_[c] = part.channel_filters_[c];
      channels_[c] = part.channels_[c];
    }
    loops_[j] = part.loops_[j];
    output_used_[j] = part.output_used_[j];
    output_sum_w_[j] = part.output_sum_w_[j];
    last_good_[j] = part.last_good_[j];
    jump_scale_[j] = part.jump_scale_[j];
    outlier_run_[j] = part.outlier_run_[j];
    screened_[j] = part.screened_[j];
    detector_.adopt_output(part.detector_, j);
    focused_.adopt_output(part.focused_, j);
    for (std::size_t k = 0; k < detector_.windows(); ++k) {
      refresh_last_[j * detector_.windows() + k] = part.refresh_last_[j * detector_.windows() + k];
      if (!info_last_.empty()) info_last_[j * detector_.windows() + k] = part.info_last_[j * detector_.windows() + k];
      refresh_count_[j * detector_.windows() + k] = part.refresh_count_[j * detector_.windows() + k];
    }
    mean_fast_[jj] = part.mean_fast_[jj];
    var_fast_[jj] = part.var_fast_[jj];
    var_baseline_[jj] = part.var_baseline_[jj];
  }
  // What every part computed alike from the same samples; raises and resets
  // are of each part's own outputs, so they add up.
  const std::uint64_t raises = counters_.raises + part.counters_.raises;
  const std::uint64_t resets = counters_.resets + part.counters_.resets;
  counters_ = part.counters_;
  counters_.raises = raises;
  counters_.resets = resets;
  in_gap_ = part.in_gap_;
  used_since_reset_ = part.used_since_reset_;
  lags_filled_ = part.lags_filled_;
  input_ref_ = part.input_ref_;
  sum_w_ = part.sum_w_;
  sum_w2_ = part.sum_w2_;
  n_eq_ = part.n_eq_;
  refresh_tick_ = part.refresh_tick_;
  refresh_cursor_ = part.refresh_cursor_;
}

}  // namespace mpm
