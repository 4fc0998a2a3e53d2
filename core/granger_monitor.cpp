#include "core/granger_monitor.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

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

bool finite_all(const double* v, std::size_t n) noexcept {
  for (std::size_t i = 0; i < n; ++i)
    if (!std::isfinite(v[i])) return false;
  return true;
}

}  // namespace

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
  bank_ = RegressorBank(n_inputs, n_outputs, na_, nb_, settings.input_pole, channel_models, first_output_, end_output_);
  warmup_ = settings.warmup > 0 ? settings.warmup : static_cast<int>(10 * p_full);

  // Factors only for the modelled outputs (the others stay empty).
  regressions_.resize(n_outputs);
  for (std::size_t j = first_output_; j < end_output_; ++j) {
    regressions_[j] = NestedRls(1 + na_, n_inputs, nb_, settings.forgetting, kRegularization, n_inputs >= kWaldMinInputs);
  }
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
  stale_.assign(n_outputs, 0);
  divergence_ = DivergenceWatch(n_outputs, reference_variance, settings.forgetting);
  screen_ = OutlierScreen(n_outputs, settings.outlier_limit);
  recovered_.assign(n_outputs, 0);
  output_used_.assign(n_outputs, 0);
  output_sum_w_.assign(n_outputs, 0.0);

  lr_raise_ = raise_threshold_at(settings.false_alarm);
  lr_joint_raise_ = joint_raise_threshold_at(settings.false_alarm);
  score_raise_ = lr_raise_;
  setup_detectors();
  reset();
}

void GrangerMonitor::reset() noexcept {
  for (std::size_t j = first_output_; j < end_output_; ++j) regressions_[j].reset();
  bank_.reset();
  in_gap_ = false;
  sum_w_ = sum_w2_ = n_eq_ = 0.0;
  std::fill(channels_.begin(), channels_.end(), ChannelStats{});
  std::fill(loops_.begin(), loops_.end(), LoopStats{});
  std::fill(stale_.begin(), stale_.end(), 0);
  divergence_.reset();
  for (auto& c : channels_) c.gamma = NAN;
  used_since_reset_ = 0;
  std::fill(output_used_.begin(), output_used_.end(), 0);
  std::fill(output_sum_w_.begin(), output_sum_w_.end(), 0.0);
  screen_.reset();
  reset_alarms();
}

void GrangerMonitor::reset_output(std::size_t j) noexcept {
  // Non-finite statistics (an input of 1e300, a factor that overflowed):
  // this output starts again from its prior; the others keep theirs.
  regressions_[j].reset();
  bank_.reset_output(j);
  output_used_[j] = 0;
  output_sum_w_[j] = 0.0;
  screen_.reset_output(j);
  reset_alarms(j);
  divergence_.reset_output(j);
  loops_[j] = LoopStats{};
  stale_[j] = 0;
  for (std::size_t i = 0; i < n_inputs_; ++i) {
    channels_[j * n_inputs_ + i] = ChannelStats{};
    channels_[j * n_inputs_ + i].gamma = NAN;
  }
  ++counters_.resets;
}

bool GrangerMonitor::ready() const noexcept { return used_since_reset_ >= static_cast<std::uint64_t>(warmup_); }

double GrangerMonitor::raise_threshold_at(double level) const noexcept {
  return chi_square_quantile_upper(level, static_cast<double>(nb_));
}

double GrangerMonitor::joint_raise_threshold_at(double level) const noexcept {
  return chi_square_quantile_upper(level, static_cast<double>(nb_ * n_inputs_));
}

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
    bank_.gap();
    return SampleStatus::kMissing;
  }
  in_gap_ = false;
  bank_.start_at(u);  // (re)start: the basis starts at rest at this level
  SampleStatus status = SampleStatus::kWarmingUp;
  if (bank_.filled()) {
    if (screen_.screen(residual)) {
      ++counters_.outliers;
      bank_.push(u, screen_.clean());
      return SampleStatus::kOutlier;
    }
    absorb_sample(residual);
    ++counters_.used;
    ++used_since_reset_;
    update_divergence(residual);
    update_statistics();
    status = SampleStatus::kUsed;
  }
  bank_.push(u, residual);
  return status;
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
    const double* ar = bank_.residual_lags(j);
    const double* lags = bank_.input_regressors(j);  // nb per input
    double* f = regressions_[j].staged_row();
    f[0] = 1.0;
    std::copy(ar, ar + na_, f + 1);
    std::copy(lags, lags + inputs, f + 1 + na_);
    f[1 + na_ + inputs] = residual[j];
  }
  NestedRls::update_staged(regressions_.data() + first_output_, end_output_ - first_output_);
}

void GrangerMonitor::update_divergence(const double* residual) noexcept {
  // Back from diverging, the output starts again (update_detector).
  for (std::size_t j = first_output_; j < end_output_; ++j)
    if (divergence_.update(j, residual[j], output_used_[j], loops_[j].diverging)) recovered_[j] = 1;
}

void GrangerMonitor::update_statistics() noexcept {
  for (std::size_t j = first_output_; j < end_output_; ++j) {
    if (loops_[j].diverging)  // no verdict on a diverging loop
      for (std::size_t i = 0; i < n_inputs_; ++i) channels_[j * n_inputs_ + i].alarm = false;
    stale_[j] = 1;
    update_detector(j);
  }
  refresh_long_windows();
}

void GrangerMonitor::refresh_statistics(std::size_t j) const noexcept {
  if (!stale_[j]) return;
  stale_[j] = 0;
  const std::size_t p_full = n_regressors();
  const std::size_t p_pair = 1 + na_ + nb_;
  const double scale_full = std::max(n_eq_ - static_cast<double>(p_full), 1.0);
  const double scale_pair = std::max(n_eq_ - static_cast<double>(p_pair), 1.0);
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
  }
}

void GrangerMonitor::adopt_outputs(const GrangerMonitor& part) {
  if (part.n_inputs_ != n_inputs_ || part.n_outputs_ != n_outputs_ || part.na_ != na_ || part.nb_ != nb_ ||
      part.bank_.lags_after_gap() != bank_.lags_after_gap() || part.warmup_ != warmup_)
    throw std::invalid_argument("adopt_outputs: the monitors differ in shape or settings");
  if (part.first_output_ < first_output_ || part.end_output_ > end_output_)
    throw std::invalid_argument("adopt_outputs: the part models outputs this monitor does not");
  for (std::size_t j = part.first_output_; j < part.end_output_; ++j) {
    regressions_[j] = part.regressions_[j];
    bank_.adopt_output(part.bank_, j);
    part.refresh_statistics(j);
    for (std::size_t i = 0; i < n_inputs_; ++i) channels_[j * n_inputs_ + i] = part.channels_[j * n_inputs_ + i];
    loops_[j] = part.loops_[j];
    stale_[j] = 0;
    output_used_[j] = part.output_used_[j];
    output_sum_w_[j] = part.output_sum_w_[j];
    screen_.adopt_output(part.screen_, j);
    detector_.adopt_output(part.detector_, j);
    focused_.adopt_output(part.focused_, j);
    for (std::size_t k = 0; k < detector_.windows(); ++k) {
      refresh_last_[j * detector_.windows() + k] = part.refresh_last_[j * detector_.windows() + k];
      if (!info_last_.empty()) info_last_[j * detector_.windows() + k] = part.info_last_[j * detector_.windows() + k];
      refresh_count_[j * detector_.windows() + k] = part.refresh_count_[j * detector_.windows() + k];
    }
    divergence_.adopt_output(part.divergence_, j);
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
  bank_.adopt_shared(part.bank_);
  sum_w_ = part.sum_w_;
  sum_w2_ = part.sum_w2_;
  n_eq_ = part.n_eq_;
  refresh_tick_ = part.refresh_tick_;
  refresh_cursor_ = part.refresh_cursor_;
}

}  // namespace mpm
