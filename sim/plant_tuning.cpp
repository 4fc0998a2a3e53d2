#include "sim/plant_tuning.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <stdexcept>

#include "core/transfer_function.hpp"
#include "sim/noise.hpp"

namespace mpm::sim {
namespace {

using Index = Eigen::Index;

constexpr long kSimulated = 20000;  // samples of each step response looked at
constexpr long kMinHorizon = 20, kMaxHorizon = 300;

Index idx(std::size_t i) { return static_cast<Index>(i); }

// Samples after which `s` stays within 1 % of `final` (of its peak when final
// is 0); s.size() if it never does (unstable, or slower than kSimulated).
long settled_after(const std::vector<double>& s, double final) {
  double peak = 0.0;
  for (double v : s) peak = std::max(peak, std::abs(v));
  const double band = 0.01 * (final != 0.0 ? std::abs(final) : peak);
  for (std::size_t n = s.size(); n-- > 0;)
    if (!(std::abs(s[n] - final) <= band)) return static_cast<long>(n) + 1;
  return 0;
}

struct ChannelScale {
  long settling = 0;
  double value = 0.0;  // steady-state gain, or final slope of an integrating channel
  bool integrates = false;
};

ChannelScale analyse(const DiscreteTf& tf) {
  DiscreteFilter filter(tf);
  std::vector<double> s(kSimulated);
  for (auto& v : s) v = filter.step(1.0);
  if (tf.has_integrator()) {
    // The step response ramps: what settles is its slope.
    for (std::size_t n = s.size(); n-- > 1;) s[n] -= s[n - 1];
    return {settled_after(s, s.back()), s.back(), true};
  }
  const double gain = tf.dc_gain();
  return {settled_after(s, gain), gain, false};
}

// Stationary std of d = N a (the impulse response's energy times var(a)).
double noise_std(const NoiseChannel& c) {
  DiscreteFilter filter(c.filter);
  double energy = 0.0;
  for (long n = 0; n < kSimulated; ++n) {
    const double h = filter.step(n == 0 ? 1.0 : 0.0);
    energy += h * h;
  }
  const double sd = std::sqrt(c.variance * energy);
  return std::isfinite(sd) ? sd : 0.0;  // an unstable N is refused by the loop itself
}

// Outputs the file gives no noise for get white noise of a tenth of the
// smallest setpoint step: visible in the recording, never swamping the steps
// (a fixed variance of 1 would for a plant whose outputs move by 0.01).
double default_noise_variance(const std::vector<double>& amplitude) {
  double smallest = INFINITY;
  for (double a : amplitude)
    if (a > 0.0) smallest = std::min(smallest, a);
  return std::isfinite(smallest) ? 0.01 * smallest * smallest : 1.0;
}

}  // namespace

PlantScales plant_scales(const PlantModel& model) {
  const std::size_t ni = model.n_inputs(), no = model.n_outputs();
  if (ni == 0 || no == 0) throw std::invalid_argument("plant-nominal: the model needs inputs and outputs");
  PlantScales s;
  s.gain = Eigen::MatrixXd::Zero(idx(no), idx(ni));
  Eigen::MatrixXd slope = Eigen::MatrixXd::Zero(idx(no), idx(ni));
  for (const auto& c : model.channels) {
    if (c.tf.is_zero()) continue;  // explicit zero: like an absent channel
    const ChannelScale cs = analyse(c.tf);
    s.settling = std::max(s.settling, cs.settling);
    (cs.integrates ? slope : s.gain)(idx(c.output), idx(c.input)) = cs.value;
  }
  s.horizon = std::clamp(s.settling, kMinHorizon, kMaxHorizon);
  // An integrating channel counts with how far a unit step has taken it one
  // horizon later: the move that matters for a setpoint change of that size.
  s.gain += slope * static_cast<double>(s.horizon);

  // Each output's steps start from the largest effect a unit move has on it;
  // the inputs those steps need (least squares: any shape of K) are then the
  // rows of K^+ diag(a), RMS over independent U(-a_j, a_j) steps. One factor
  // scales all amplitudes so that the geometric mean of those RMS moves is
  // 1 unit: an ill-conditioned plant moves some inputs more than others, and
  // the mean keeps the least-moved ones visible without the most-moved ones
  // running off (the 4x4 tank: 0.4 .. 4.2 units).
  Eigen::VectorXd a(idx(no));
  for (Index j = 0; j < a.size(); ++j) a(j) = s.gain.row(j).cwiseAbs().maxCoeff();
  s.gain_inverse = s.gain.completeOrthogonalDecomposition().pseudoInverse();
  Eigen::VectorXd b = (s.gain_inverse * a.asDiagonal()).rowwise().norm() / std::sqrt(3.0);
  double log_sum = 0.0;
  long moved = 0;
  for (double v : b) {
    if (!(v > 0.0)) continue;  // an input no output needs
    log_sum += std::log(v);
    ++moved;
  }
  const double scale = moved > 0 ? std::exp(-log_sum / static_cast<double>(moved)) : 1.0;
  a *= scale;
  b *= scale;
  s.amplitude.assign(a.data(), a.data() + a.size());
  s.move.assign(b.data(), b.data() + b.size());

  for (const auto& c : noise_channels(model, default_noise_variance(s.amplitude))) s.noise_std.push_back(noise_std(c));
  return s;
}

LoopConfig tuned_loop(const PlantModel& model) {
  const PlantScales s = plant_scales(model);
  const std::size_t ni = model.n_inputs(), no = model.n_outputs();
  const auto horizon = static_cast<std::size_t>(s.horizon);
  LoopConfig c;
  c.default_noise_variance = default_noise_variance(s.amplitude);

  // P covers the slowest channel's settling (DMC sees every move's full
  // effect; capped so a very slow plant does not make the dynamic matrix
  // huge); M of a tenth of it, 5..10 moves, shapes the transient without
  // making the QP large.
  c.mpc.prediction_horizon = horizon;
  c.mpc.control_horizon = std::clamp<std::size_t>(horizon / 10, 5, 10);

  // Q_j = 1/a_j^2: every output's error counts relative to its own step, so
  // outputs of different scale count alike (0 for an output nothing moves).
  c.mpc.output_weights.resize(no);
  for (std::size_t j = 0; j < no; ++j)
    c.mpc.output_weights[j] = s.amplitude[j] > 0.0 ? 1.0 / (s.amplitude[j] * s.amplitude[j]) : 0.0;

  // R_l = rho sum_j Q_j K_jl^2: a move is charged like the (scaled) output
  // change it causes, as in Shridhar & Cooper's DMC move suppression, with
  // their factor rho = M/10 (3.5 tau/T + 2 - (M-1)/2) and tau/T ~ settling/4.6
  // (first order). That gives little overshoot and moderate moves, not bang-bang.
  const double m = static_cast<double>(c.mpc.control_horizon);
  const double rho = m / 10.0 * (3.5 * static_cast<double>(horizon) / 4.6 + 2.0 - (m - 1.0) / 2.0);
  std::vector<double> effect(ni, 0.0);
  for (std::size_t l = 0; l < ni; ++l)
    for (std::size_t j = 0; j < no; ++j)
      effect[l] += c.mpc.output_weights[j] * s.gain(idx(j), idx(l)) * s.gain(idx(j), idx(l));
  const double largest = *std::max_element(effect.begin(), effect.end());
  c.mpc.move_weights.resize(ni);
  for (std::size_t l = 0; l < ni; ++l)  // an input that moves nothing still needs R > 0
    c.mpc.move_weights[l] = rho * (largest > 0.0 ? std::max(effect[l], 1e-3 * largest) : 1.0);

  // Limits: twice the worst-case input that holds every output at the edge
  // of its setpoint range against a 3-sigma disturbance, so they bind only in
  // rare transients; 1 unit for an input that moves nothing.
  c.mpc.input_lower.resize(ni);
  c.mpc.input_upper.resize(ni);
  for (std::size_t l = 0; l < ni; ++l) {
    double need = 0.0;
    for (std::size_t j = 0; j < no; ++j)
      need += std::abs(s.gain_inverse(idx(l), idx(j))) * (s.amplitude[j] + 3.0 * s.noise_std[j]);
    const double limit = need > 0.0 ? 2.0 * need : 1.0;
    c.mpc.input_lower[l] = -limit;
    c.mpc.input_upper[l] = limit;
  }

  // Random steps on every output, a new level every 3..6 settling times: the
  // loop settles between changes and a few thousand samples hold several.
  c.setpoints.resize(no);
  for (std::size_t j = 0; j < no; ++j) {
    c.setpoints[j].random_amplitude = s.amplitude[j];
    c.setpoints[j].random_period_min = 3 * s.horizon;
    c.setpoints[j].random_period_max = 6 * s.horizon;
  }
  // Three settling times before t = 0: the noise filters and the loop are in
  // steady operation when the recording starts.
  c.warmup = 3 * s.horizon;
  return c;
}

}  // namespace mpm::sim
