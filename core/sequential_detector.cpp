#include "core/sequential_detector.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "core/chi_square.hpp"

namespace mpm {
namespace {

constexpr double kSecondsPerYear = 365.25 * 86400.0;
// Threshold table of the growing phase: kTableSteps effective memories per
// octave, down to kShortestEffective samples.
constexpr double kTableSteps = 4.0;
constexpr double kShortestEffective = 16.0;

double log_chi_square_density(double h, double dof) noexcept {
  const double k = 0.5 * dof;
  return (k - 1.0) * std::log(h) - 0.5 * h - k * std::log(2.0) - std::lgamma(k);
}

}  // namespace

const std::vector<FieldRow<DetectorSettings>>& DetectorSettings::fields() {
  using S = DetectorSettings;
  static const std::vector<FieldRow<S>> rows = {
      {"false_alarms_per_year", [](S& s) { return &s.false_alarms_per_year; }, {.min = 0.0, .max = 1e9, .min_open = true},
       "live alarms: stated false-alarm rate for the whole controller"},
      {"sample_time", [](S& s) { return &s.sample_time; }, {.min = 0.0, .max = 1e6},
       "seconds per sample (0: the plant's)"},
      {"windows", [](S& s) { return &s.windows; }, {.min = 1, .max = 16, .whole = true}, "detector memories"},
      {"first_window", [](S& s) { return &s.first_window; }, {.min = 2.0, .max = 1e7, .also = 0.0},
       "shortest memory in samples (0: 2 / (1 - forgetting))"},
      {"window_ratio", [](S& s) { return &s.window_ratio; }, {.min = 1.5, .max = 100.0}, "ratio of successive memories"},
      {"crossing_constant", [](S& s) { return &s.crossing_constant; }, {.min = 0.0, .max = 100.0, .min_open = true},
       "the detector's crossing-rate constant (from mpm calibrate)"},
      {"clear_fraction", [](S& s) { return &s.clear_fraction; }, {.min = 0.0, .max = 1.0, .max_open = true},
       "clear level = d + fraction (h_W - d)"},
      {"detector_thresholds", [](S& s) { return &s.thresholds; }, {},
       "one threshold per memory, from mpm calibrate (empty: from the rate)"},
  };
  return rows;
}

std::vector<FieldError> DetectorSettings::errors() const {
  std::vector<FieldError> e = range_errors(fields(), *this);
  if (!thresholds.empty() && thresholds.size() != static_cast<std::size_t>(windows))
    e.push_back({"detector_thresholds", "detector_thresholds: need one per window (" + std::to_string(windows) +
                                            "), got " + std::to_string(thresholds.size())});
  for (double h : thresholds)
    if (!(std::isfinite(h) && h > 0.0))
      e.push_back({"detector_thresholds", "detector_thresholds must be finite and > 0, got " + std::to_string(h)});
  if (rate_per_sample() >= 0.1)
    e.push_back({"false_alarms_per_year", "false_alarms_per_year x sample_time is more than 0.1 alarms per sample"});
  return e;
}

double DetectorSettings::rate_per_sample() const noexcept {
  return false_alarms_per_year * (sample_time > 0.0 ? sample_time : 1.0) / kSecondsPerYear;
}

double crossing_rate(double h, double dof, double window, double period, double c) noexcept {
  if (!(h > dof)) return INFINITY;
  return c * std::exp(log_chi_square_density(h, dof)) * 2.0 * (h - dof) / window *
         std::exp(-kOvershootBeta * std::sqrt(period / window));
}

double crossing_threshold(double rate, double dof, double window, double period, double c) noexcept {
  // The rate rises from 0 at h = dof, peaks, then falls: bisect on log rate
  // from well above the peak (dof + 2 sqrt(2 dof) + 2 is past it).
  double lo = dof + 2.0 * std::sqrt(2.0 * dof) + 2.0;
  double hi = lo;
  const double target = std::log(rate);
  const auto log_rate = [&](double h) { return std::log(crossing_rate(h, dof, window, period, c)); };
  // Never below the chi-square's 1e-2 upper quantile: the formula holds for
  // high levels only, and a window whose share of a high stated rate would
  // need a level in the bulk of the distribution (a long window at a rate
  // of one alarm in 10^4 samples) contributes less than its share instead.
  lo = std::max(lo, chi_square_quantile_upper(1e-2, dof));
  if (log_rate(lo) <= target) return lo;
  while (log_rate(hi) > target && hi < 1e6) hi *= 2.0;
  for (int it = 0; it < 200 && hi - lo > 1e-9 * hi; ++it) {
    const double mid = 0.5 * (lo + hi);
    (log_rate(mid) > target ? lo : hi) = mid;
  }
  return hi;
}

SequentialDetector::SequentialDetector(std::size_t outputs, std::size_t dof, const DetectorSettings& settings,
                                       std::size_t outputs_sharing_rate, double long_period, double first_period)
    : outputs_(outputs), dof_(dof) {
  const std::vector<double>& thresholds = settings.thresholds;
  if (const std::string err = settings.validate(); !err.empty()) throw std::invalid_argument(err);
  if (dof == 0) throw std::invalid_argument("SequentialDetector: need at least one degree of freedom");
  const auto k = static_cast<Eigen::Index>(settings.windows);
  if (!thresholds.empty() && thresholds.size() != static_cast<std::size_t>(k))
    throw std::invalid_argument("detector thresholds: need one per window");
  window_.resize(k);
  rho_.resize(k);
  threshold_.resize(k);
  clear_.resize(k);
  const double share =
      settings.rate_per_sample() / static_cast<double>(std::max<std::size_t>(outputs_sharing_rate, 1) * static_cast<std::size_t>(k));
  const auto d = static_cast<double>(dof);
  dof_value_ = d;
  clear_fraction_ = settings.clear_fraction;
  const double longest = settings.first_window * std::pow(settings.window_ratio, static_cast<double>(k - 1));
  const auto steps = static_cast<Eigen::Index>(
      1 + std::ceil(kTableSteps * std::log2(std::max(longest / kShortestEffective, 1.0))));
  threshold_table_.resize(steps, k);
  for (Eigen::Index w = 0; w < k; ++w) {
    window_[w] = settings.first_window * std::pow(settings.window_ratio, static_cast<double>(w));
    rho_[w] = 1.0 - 1.0 / window_[w];
    const double period = w == 0 ? first_period : long_period;
    // The window's crossing constant: the setting's, or the one that gives a
    // calibrated threshold (from `mpm calibrate`) its share of the rate, so
    // the growing phase is scaled alike.
    double c = settings.crossing_constant;
    if (!thresholds.empty()) {
      const double h = thresholds[static_cast<std::size_t>(w)];
      if (!(std::isfinite(h) && h > 0.0)) throw std::invalid_argument("detector thresholds must be finite and > 0");
      const double unit = crossing_rate(h, d, window_[w], period, 1.0);
      c = std::isfinite(unit) && unit > 0.0 ? std::clamp(share / unit, 1e-6, 1e6) : 1e6;
    }
    for (Eigen::Index g = 0; g < steps; ++g) {
      const double eff = std::max(window_[w] * std::exp2(-static_cast<double>(g) / kTableSteps), kShortestEffective);
      threshold_table_(g, w) = crossing_threshold(share, d, eff, period, c);
    }
    if (!thresholds.empty()) threshold_table_(0, w) = thresholds[static_cast<std::size_t>(w)];
    // Never below the stationary level (the formula's floor can cross over).
    for (Eigen::Index g = 1; g < steps; ++g) threshold_table_(g, w) = std::max(threshold_table_(g, w), threshold_table_(g - 1, w));
    threshold_[w] = threshold_table_(0, w);
    clear_[w] = d + settings.clear_fraction * std::max(threshold_[w] - d, 0.0);
  }
  sums_.resize(static_cast<Eigen::Index>(dof), static_cast<Eigen::Index>(outputs * static_cast<std::size_t>(k)));
  last_.assign(outputs * static_cast<std::size_t>(k), 0.0);
  raised_.assign(outputs, 0);
  cursor_.assign(outputs, 0);
  info_.assign(outputs * static_cast<std::size_t>(k), Eigen::MatrixXd());
  chol_.assign(outputs * static_cast<std::size_t>(k), factored_identity(0));
  for (std::size_t j = 0; j < outputs; ++j)
    for (Eigen::Index w = 1; w < k; ++w) {
      info_[j * static_cast<std::size_t>(k) + static_cast<std::size_t>(w)] = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(dof), static_cast<Eigen::Index>(dof));
      chol_[j * static_cast<std::size_t>(k) + static_cast<std::size_t>(w)] = factored_identity(static_cast<Eigen::Index>(dof));
    }
  info_ok_.assign(outputs * static_cast<std::size_t>(k), 0);
  var_.assign(outputs * static_cast<std::size_t>(k), 0.0);
  var_norm_.assign(outputs * static_cast<std::size_t>(k), 0.0);
  solve_ = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(dof));
  reset();
}

void SequentialDetector::accumulate(std::size_t j, const double* x, double scale, double squared_error) noexcept {
  const std::size_t kw = windows();
  const auto d = static_cast<Eigen::Index>(dof_);
  for (std::size_t w = 0; w < kw; ++w) {
    const double r2 = rho_[static_cast<Eigen::Index>(w)] * rho_[static_cast<Eigen::Index>(w)];
    var_[j * kw + w] = r2 * var_[j * kw + w] + squared_error;
    var_norm_[j * kw + w] = r2 * var_norm_[j * kw + w] + 1.0;
    double* s = sums_.col(static_cast<Eigen::Index>(j * kw + w)).data();
    const double r = rho_[static_cast<Eigen::Index>(w)];
    for (Eigen::Index i = 0; i < d; ++i) s[i] = r * s[i] + scale * x[i];
  }
}

void SequentialDetector::information_inverse(std::size_t j, std::size_t k, Eigen::MatrixXd& out) const noexcept {
  out.setIdentity();
  chol_[j * windows() + k].solveInPlace(out);
}

DetectorEvent SequentialDetector::test(std::size_t j, std::size_t k, double t) noexcept {
  const std::size_t kw = windows();
  last_[j * kw + k] = t;
  if (!raised_[j]) {
    if (t > threshold_now(j, k)) {
      raised_[j] = 1;
      return DetectorEvent::kRaised;
    }
    return DetectorEvent::kNone;
  }
  for (std::size_t w = 0; w < kw; ++w)
    if (!(last_[j * kw + w] < dof_value_ + clear_fraction_ * std::max(threshold_now(j, w) - dof_value_, 0.0)))
      return DetectorEvent::kNone;
  raised_[j] = 0;
  return DetectorEvent::kCleared;
}

double SequentialDetector::threshold_now(std::size_t j, std::size_t k) const noexcept {
  // Effective memory 2 V: the relaxation rate of T_W is 1 / V (2 / W once
  // full, 1 / n while the window grows), the rate formula's 2 / W.
  const auto kk = static_cast<Eigen::Index>(k);
  const double eff = 2.0 * var_norm_[j * windows() + k];
  if (!(eff < window_[kk])) return threshold_table_(0, kk);
  // Linear in log memory between the table's entries.
  const double g = kTableSteps * std::log2(window_[kk] / std::max(eff, 1.0));
  const auto last = threshold_table_.rows() - 1;
  const auto below = std::min(static_cast<Eigen::Index>(g), last);
  if (below == last) return threshold_table_(last, kk);
  const double f = g - static_cast<double>(below);
  return (1.0 - f) * threshold_table_(below, kk) + f * threshold_table_(below + 1, kk);
}

std::size_t SequentialDetector::strongest(std::size_t j) const noexcept {
  std::size_t best = 0;
  for (std::size_t w = 1; w < windows(); ++w)
    if (last_[j * windows() + w] / threshold_now(j, w) > last_[j * windows() + best] / threshold_now(j, best))
      best = w;
  return best;
}

void SequentialDetector::reset_output(std::size_t j) noexcept {
  const std::size_t kw = windows();
  for (std::size_t w = 0; w < kw; ++w) {
    sums_.col(static_cast<Eigen::Index>(j * kw + w)).setZero();
    last_[j * kw + w] = 0.0;
    if (!var_.empty()) var_[j * kw + w] = var_norm_[j * kw + w] = 0.0;
  }
  raised_[j] = 0;
  cursor_[j] = 0;
  for (std::size_t w = 1; w < kw; ++w) {
    info_[j * kw + w].setZero();
    info_ok_[j * kw + w] = 0;
  }
}

void SequentialDetector::refresh_information(std::size_t j, std::size_t k, const Eigen::MatrixXd& per_sample,
                                             double gap) noexcept {
  const std::size_t i = j * windows() + k;
  const double r2 = rho_[static_cast<Eigen::Index>(k)] * rho_[static_cast<Eigen::Index>(k)];
  const double decay = std::pow(r2, gap);
  // The samples since the last refresh, each with its weight rho^2j, carry
  // the current per-sample information.
  const double weight = (1.0 - decay) / (1.0 - r2);
  info_[i] *= decay;
  info_[i].noalias() += weight * per_sample;
  chol_[i].compute(info_[i]);
  info_ok_[i] = chol_[i].info() == Eigen::Success ? 1 : 0;
}

double SequentialDetector::normalised_quadratic(std::size_t j, std::size_t k) noexcept {
  const std::size_t i = j * windows() + k;
  solve_ = sums_.col(static_cast<Eigen::Index>(i));
  chol_[i].matrixL().solveInPlace(solve_);
  return solve_.squaredNorm();
}

void SequentialDetector::reset() noexcept {
  for (std::size_t j = 0; j < outputs_; ++j) reset_output(j);
}

void SequentialDetector::adopt_output(const SequentialDetector& part, std::size_t j) noexcept {
  const std::size_t kw = windows();
  for (std::size_t w = 0; w < kw; ++w) {
    sums_.col(static_cast<Eigen::Index>(j * kw + w)) = part.sums_.col(static_cast<Eigen::Index>(j * kw + w));
    last_[j * kw + w] = part.last_[j * kw + w];
    var_[j * kw + w] = part.var_[j * kw + w];
    var_norm_[j * kw + w] = part.var_norm_[j * kw + w];
  }
  raised_[j] = part.raised_[j];
  cursor_[j] = part.cursor_[j];
  for (std::size_t w = 1; w < kw; ++w) {
    info_[j * kw + w] = part.info_[j * kw + w];
    info_ok_[j * kw + w] = part.info_ok_[j * kw + w];
    chol_[j * kw + w] = part.chol_[j * kw + w];
  }
}

}  // namespace mpm
