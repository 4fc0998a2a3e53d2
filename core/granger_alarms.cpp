// The live alarms of the Granger monitor (granger_monitor.hpp, "Live
// alarms"): the sequential detectors' setup, the score each used sample
// adds, the long windows' periodic information refresh, and what a
// statistic crossing or falling back below its threshold does (raise or
// clear the output, name the channel).
#include <algorithm>
#include <cmath>

#include "core/granger_monitor.hpp"

namespace mpm {
namespace {

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

}  // namespace

void GrangerMonitor::setup_detectors() {
  // The stated rate is the whole controller's: shared by all its outputs,
  // also when this monitor models only a part of them.
  const std::size_t d = n_inputs_ * nb_;
  // The shortest memory is the one whose squared weights equal the factor's
  // (rho^2 = lambda): there S is exactly the score's conditional variance,
  // however the inputs moved, so T is chi-square even across setpoint steps
  // (measured: shorter windows normalised by S raise on every step).
  DetectorSettings detector = settings_.detector;
  if (d > kLongWindowMaxDof) {
    detector.windows = 1;
    if (detector.thresholds.size() > 1) detector.thresholds.erase(detector.thresholds.begin() + 1, detector.thresholds.end());
  }
  if (detector.first_window == 0.0)
    detector.first_window = settings_.forgetting < 1.0 ? std::min(2.0 / (1.0 - settings_.forgetting), 1e6) : 2000.0;
  // Long windows are looked at when their information is refreshed: one
  // (output, window) every kRefreshEvery samples, round robin.
  const double long_period = static_cast<double>(kRefreshEvery * n_outputs_ * static_cast<std::size_t>(std::max(detector.windows - 1, 1)));
  // Two statistics share the stated rate (Bonferroni): the full score (m nb
  // dof) and the focused one (m dof), whose threshold at the same rate is
  // far lower, so a mismatch in the direction it tests (a gain, mostly
  // also a time constant or dead time of a model-filtered channel) crosses
  // it with a fraction of the samples.
  detector.false_alarms_per_year *= 0.5;
  detector_ = SequentialDetector(n_outputs_, d, detector, n_outputs_, long_period,
                                 static_cast<double>(kFirstWindowEvery));
  DetectorSettings focused = detector;
  focused.thresholds.clear();  // `mpm calibrate` fits the full score's
  // The focused first window is looked at with every refresh of its output.
  focused_ = SequentialDetector(n_outputs_, n_inputs_, focused, n_outputs_, long_period,
                                static_cast<double>(kRefreshEvery * n_outputs_));
  focused_dir_ = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(nb_), static_cast<Eigen::Index>(n_outputs_));
  for (std::size_t j = 0; j < n_outputs_; ++j) {
    auto v = focused_dir_.col(static_cast<Eigen::Index>(j));
    v[0] = 1.0;
    if (settings_.input_pole == 0.0 && n_inverse_ar_[j])
      for (std::size_t l = 1; l < nb_ && l <= na_; ++l) v[static_cast<Eigen::Index>(l)] = -(*n_inverse_ar_[j])[static_cast<Eigen::Index>(l - 1)];
    v.normalize();
  }
  focused_row_ = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n_inputs_));
  focused_info_ = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(n_inputs_), static_cast<Eigen::Index>(n_inputs_));
  focused_llt_ = factored_identity(static_cast<Eigen::Index>(n_inputs_));
  focused_solve_ = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n_inputs_));
  score_scratch_ = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(d));
  locate_cov_ = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(d), static_cast<Eigen::Index>(d));
  locate_v_ = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(d));
  locate_block_ = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(nb_), static_cast<Eigen::Index>(nb_));
  locate_x_ = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(nb_));
  locate_llt_ = factored_identity(static_cast<Eigen::Index>(nb_));
  if (detector_.windows() > 1) {
    info_scratch_ = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(d), static_cast<Eigen::Index>(d));
    info_llt_ = factored_identity(static_cast<Eigen::Index>(d));
    info_last_.assign(n_outputs_ * detector_.windows(), Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(d), static_cast<Eigen::Index>(d)));
  }
  // The score starts once the factor's memory is full: before, the AR
  // reference and S are estimates from a few hundred samples and the score
  // is heavy tailed (measured: raises ~100 samples after the warm-up).
  burn_in_ = std::max<std::uint64_t>(static_cast<std::uint64_t>(warmup_),
                                     settings_.forgetting < 1.0 ? static_cast<std::uint64_t>(std::min(1.0 / (1.0 - settings_.forgetting), 1e6)) : 0);
  // The score accumulates from the factor's first sample, so the first
  // window's weights (rho_0^2 = lambda) are those of S, its normaliser,
  // from the start: started at the burn-in instead, its few hundred recent
  // samples were normalised by S of the whole memory and crossed whenever
  // the excitation had moved (measured: raises clustered right after the
  // burn-in on all three plants).
  score_start_ = 1;
  refresh_last_.assign(n_outputs_ * detector_.windows(), score_start_);
  refresh_count_.assign(n_outputs_ * detector_.windows(), 0);
}

void GrangerMonitor::reset_alarms() noexcept {
  detector_.reset();
  focused_.reset();
  std::fill(refresh_last_.begin(), refresh_last_.end(), score_start_);
  for (Eigen::MatrixXd& m : info_last_) m.setZero();
  std::fill(refresh_count_.begin(), refresh_count_.end(), 0);
  refresh_tick_ = 0;
  refresh_cursor_ = 0;
}

void GrangerMonitor::reset_alarms(std::size_t j) noexcept {
  detector_.reset_output(j);
  focused_.reset_output(j);
  for (std::size_t k = 0; k < detector_.windows(); ++k) {
    refresh_last_[j * detector_.windows() + k] = score_start_;
    if (!info_last_.empty()) info_last_[j * detector_.windows() + k].setZero();
    refresh_count_[j * detector_.windows() + k] = 0;
  }
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
  refresh_statistics(j);  // gamma and the pairwise F, for the paper's rule
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

}  // namespace mpm
