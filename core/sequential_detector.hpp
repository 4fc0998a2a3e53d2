// OVERVIEW
// Sequential detection of a mismatch in one output's regression, with a
// stated false-alarm rate per unit time (not per look).
//
// Why not a chi-square test every sample: a statistic re-tested every
// sample at probability alpha raises, over an unbounded stream, about
// alpha x (samples / its correlation time) times: the false alarms grow with
// the record (measured: 39 % of 20 000-sample Wood-Berry runs). A detector
// for streams is stated as a rate (Page 1954, Lorden 1971: mean time between
// false alarms), so the thresholds below are derived from a rate per sample.
//
// The statistic: the score (Lagrange-multiplier) test of the inputs' block
// B against the AR-only reference model [1, AR], accumulated with the
// memories W of a few exponential windows at once (a window-limited GLR in
// the sense of Lai 1998, with exponential instead of rectangular windows).
// With e_k the a-priori AR-only prediction error and x~_k the a-priori
// residual of the input regressors given [1, AR] (both left by the shared
// trapezoid of NestedRls, with its conversion weight w_k),
//   g_k = w_k e_k x~_k,   s_W(k) = rho_W s_W(k-1) + g_k,   rho_W = 1 - 1/W,
//   T_W = n / (sigma^2 V_W) * s_W^T S^-1 s_W,   V_W = sum_{i<k} rho_W^2i,
// S the (forgetting-weighted) information of x~, n the sum of the weights,
// sigma^2 = RSS(AR only) / n. Under "no causality" g_k is a martingale
// difference with covariance sigma^2 S / n, so s_W has covariance
// sigma^2 V_W S / n and T_W is chi-square with d = m nb degrees of freedom
// at every k, from the first sample: V_W is the weight actually
// accumulated, not the stationary 1 / (1 - rho_W^2), which made T_W
// underestimate by ~2k/W while k < W. While k << W, T_W is the growing-
// window (offline) test; as W grows to the record length it becomes
// the offline joint LR test (the score and LR tests agree to first order),
// which is what lets a small concealed mismatch accumulate evidence over
// 10^4..10^5 samples while a large one crosses a short window in ~10^2.
//
// Thresholds: T_W is a chi-square process that relaxes to its mean d at the
// rate 2/W per sample (E[dT | T = h] = -2 (h - d) / W). With hysteresis (an
// excursion ends when T_W falls back to a clear level well below h) the
// rate of excursions above a high level h is, as for any diffusion, its
// stationary density times the speed at which it is pushed back (the first-
// passage form of Rice's formula; Siegmund 1985 ch. 10), with a correction
// for looking at T_W only every `period` samples: a discrete walk
// overshoots the level, so it is seen crossing less often (Siegmund's
// exp(-2 rho sigma ...) correction; Basseville & Nikiforov 1993 sec. 5.2):
//   rate_W(h) ~ c * f_d(h) * 2 (h - d) / W * exp(-beta * sqrt(period / W)),
// f_d the chi-square density. c and beta were fitted by simulation of the
// ideal process (d = 10, 20, 40; W = 100..6400; period 6; 4e6 samples each;
// tests/core/test_sequential_detector.cpp checks the rate, growing phase
// included, on that process at d = 4 with c = 1.2: 0.78 x the stated rate,
// 95 % CI 0.63..0.96, 39 of 94 raises in the first half) and `mpm calibrate` refits c on a plant's own closed
// loop. The stated rate of the whole controller is split equally over
// statistics x outputs x windows (Bonferroni) and each h_W solves
// rate_W(h_W) = share.
//
// Growing phase: T_W relaxes at the rate 1 / V_W (E[T' - T | T] =
// -(T - d) / V_W: 2 / W once full, 1 / k while k << W), so at first it
// crosses a level far more often than the stationary formula says (the
// law-of-the-iterated-logarithm regime: a growing-window chi-square process
// in log time). The threshold therefore follows the effective memory:
// h_W(k) = h for a window of memory min(2 V_W, W), from a table fixed at
// setup (4 memories per octave, linear in log memory between them), so the rate per sample stays the share from the first
// look on (flat in time) and the thresholds fall to the stationary ones as
// the window fills. Calibrated thresholds (`mpm calibrate`) fix each
// window's constant c_W, and the table is scaled by it. An output
// raises when any T_W > h_W and clears when every T_W is below its clear
// level d + f (h_W(k) - d) (one raise per excursion).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "core/field_table.hpp"

namespace mpm {

// A Cholesky factor of the n x n identity: storage sized at setup and every
// member set. Eigen's default and size constructors leave the factor's
// status unset, and copying such an object (a vector fill, a monitor copy)
// reads it: undefined behaviour that UBSan reports.
inline Eigen::LLT<Eigen::MatrixXd> factored_identity(Eigen::Index n) {
  return Eigen::LLT<Eigen::MatrixXd>(Eigen::MatrixXd::Identity(n, n));
}

// Fitted by simulation of the ideal chi-square process (see the overview).
inline constexpr double kCrossingConstant = 0.7;
inline constexpr double kOvershootBeta = 3.5;

struct DetectorSettings {
  double false_alarms_per_year = 1.0;  // stated rate for the whole controller
  double sample_time = 0.0;            // seconds per sample; 0 = the plant's
                                       // (filled in by the front end; 1 s if none)
  int windows = 4;                     // memories first_window * ratio^k
  double first_window = 0.0;           // samples; 0 = 2 / (1 - forgetting) (2000
                                       // when forgetting = 1): see below
  double window_ratio = 4.0;
  double crossing_constant = kCrossingConstant;  // c in rate_W(h)
  double clear_fraction = 0.5;         // clear level = d + fraction (h_W - d)
  std::vector<double> thresholds;      // per window, from `mpm calibrate`;
                                       // empty = derived from the rate

  // One row per setting (field_table.hpp): keys, ranges, help.
  static const std::vector<FieldRow<DetectorSettings>>& fields();
  // Every setting out of its range, then what the settings break together.
  std::vector<FieldError> errors() const;
  std::string validate() const { return joined(errors()); }  // "" when valid
  bool operator==(const DetectorSettings&) const = default;
  // Rate per sample for the whole controller.
  double rate_per_sample() const noexcept;
};

// Approximate rate per sample at which T_W upcrosses h (see the overview).
double crossing_rate(double h, double dof, double window, double period, double c) noexcept;
// h with crossing_rate(h) = rate (bisection; setup only).
double crossing_threshold(double rate, double dof, double window, double period, double c) noexcept;

// Change event of one output.
enum class DetectorEvent : std::int8_t { kNone = 0, kRaised = 1, kCleared = -1 };

class SequentialDetector {
 public:
  SequentialDetector() = default;
  // outputs x windows sums of `dof` values each; thresholds from the stated
  // rate shared by `outputs_sharing_rate` outputs, the first window looked
  // at every `first_period` samples and the others every `long_period`, or
  // settings.thresholds when given.
  SequentialDetector(std::size_t outputs, std::size_t dof, const DetectorSettings& settings,
                     std::size_t outputs_sharing_rate, double long_period, double first_period = 1.0);

  std::size_t windows() const noexcept { return static_cast<std::size_t>(window_.size()); }
  std::size_t dof() const noexcept { return dof_; }
  double window(std::size_t k) const noexcept { return window_[static_cast<Eigen::Index>(k)]; }
  // The stationary threshold and clear level of window k (its memory full).
  double threshold(std::size_t k) const noexcept { return threshold_[static_cast<Eigen::Index>(k)]; }
  double clear_level(std::size_t k) const noexcept { return clear_[static_cast<Eigen::Index>(k)]; }
  // The weight window k of output j has accumulated, V = sum_i rho_W^2i over
  // the samples since its start (1 / (1 - rho_W^2) once full): s_W's
  // variance is sigma^2 V times the information per sample, so T_W is
  // normalised by V, chi-square from the first sample.
  double weight(std::size_t j, std::size_t k) const noexcept { return var_norm_[j * windows() + k]; }
  // The threshold of window k of output j now: that of an effective memory
  // min(2 V, W) (see the overview: growing phase). Real-time safe.
  double threshold_now(std::size_t j, std::size_t k) const noexcept;

  // Real-time safe: s_W <- rho_W s_W + scale * x for every window of output
  // j, and the window's noise variance from the squared prediction error
  // (weighted, w e^2) with weights rho_W^2: a long window normalised by a
  // variance of shorter memory would cross as often as that memory's
  // fluctuations, whatever its own length (measured: crossing constants
  // growing ~W).
  void accumulate(std::size_t j, const double* x, double scale, double squared_error) noexcept;
  // The window's noise variance (sigma_W^2).
  double variance(std::size_t j, std::size_t k) const noexcept {
    const std::size_t i = j * windows() + k;
    return var_norm_[i] > 0.0 ? var_[i] / var_norm_[i] : 0.0;
  }
  const double* sum(std::size_t j, std::size_t k) const noexcept {
    return sums_.col(static_cast<Eigen::Index>(j * windows() + k)).data();
  }
  // Windows past the first are normalised by their own information J_W (the
  // ρ_W^2-weighted sum of the per-sample information, refreshed every so
  // often with what the samples since the last refresh brought: the
  // monitor passes the increment of S over the gap, not the snapshot S/n,
  // which lags the score after a loss of excitation): S alone has the factor's memory, and a window much
  // longer than it, normalised by S, saw its statistic inflated by the
  // excitation of setpoint steps S had forgotten (measured by mpm
  // calibrate: crossing constants 6..1400 instead of ~1). Real-time safe.
  // per_sample: d x d information per sample; gap: samples since the last refresh.
  void refresh_information(std::size_t j, std::size_t k, const Eigen::MatrixXd& per_sample, double gap) noexcept;
  bool has_information(std::size_t j, std::size_t k) const noexcept { return info_ok_[j * windows() + k] != 0; }
  // s_W^T J_W^-1 s_W (window k >= 1, has_information). Real-time safe.
  double normalised_quadratic(std::size_t j, std::size_t k) noexcept;
  // J_W^-1 into out (dof x dof, column major; has_information). O(dof^3),
  // real-time safe: for a raise.
  void information_inverse(std::size_t j, std::size_t k, Eigen::MatrixXd& out) const noexcept;
  // Records T for window k of output j. Real-time safe.
  DetectorEvent test(std::size_t j, std::size_t k, double t) noexcept;

  bool raised(std::size_t j) const noexcept { return raised_[j] != 0; }
  // Last T of each window of output j, and the window with the most evidence
  // (largest T_W / h_W).
  double last(std::size_t j, std::size_t k) const noexcept { return last_[j * windows() + k]; }
  std::size_t strongest(std::size_t j) const noexcept;
  void reset_output(std::size_t j) noexcept;
  void reset() noexcept;
  // Output j's state from `part`, a detector of the same shape.
  void adopt_output(const SequentialDetector& part, std::size_t j) noexcept;

  // Every member that changes after setup (for checkpointing).
  template <class V>
  void visit_state(V&& v) {
    v(sums_);
    v(last_);
    v(raised_);
    v(cursor_);
    v(var_);
    v(var_norm_);
    for (Eigen::MatrixXd& m : info_) v(m);
    v(info_ok_);
  }

 private:
  std::size_t outputs_ = 0;
  std::size_t dof_ = 0;
  double dof_value_ = 0.0, clear_fraction_ = 0.5;
  Eigen::VectorXd window_, rho_, threshold_, clear_;
  // threshold_table_(g, k): window k's threshold at an effective memory
  // W_k 2^(-g / kTableSteps) (g = 0: the stationary one).
  Eigen::MatrixXd threshold_table_;
  Eigen::MatrixXd sums_;            // dof x (outputs * windows)
  std::vector<double> last_;        // outputs * windows
  std::vector<std::uint8_t> raised_;
  std::vector<std::uint32_t> cursor_;
  std::vector<double> var_, var_norm_;           // per (output, window)
  std::vector<Eigen::MatrixXd> info_;           // J_W per (output, window >= 1)
  std::vector<std::uint8_t> info_ok_;
  std::vector<Eigen::LLT<Eigen::MatrixXd>> chol_;  // its Cholesky factor (derived: not state)
  Eigen::VectorXd solve_;                       // scratch, dof
};

}  // namespace mpm
