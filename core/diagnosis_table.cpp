// The hypothesis table: one row per form of a physics word. Read a row as
// "at this scope, where `applies` holds, fit this form with so many
// parameters; accept it only through this gate; say it with this sentence".
#include "core/diagnosis_table.hpp"

#include <array>
#include <string_view>

namespace mpm::diagnosis {
namespace {

bool modelled_channel(const Context& cx, const Site& s) { return cx.excited[s.input] && cx.has_channel(s.output, s.input); }
bool unmodelled_channel(const Context& cx, const Site& s) {
  return cx.excited[s.input] && !cx.has_channel(s.output, s.input);
}
// A slow enough mode to change (a pole below 0.2 settles within a sample or two).
bool slow_mode(const Context& cx, const Site& s) {
  return modelled_channel(cx, s) && slowest_pole(*cx.channel(s.output, s.input)) >= 0.2;
}
bool self_regulating(const Context& cx, const Site& s) {
  return modelled_channel(cx, s) && !cx.channel(s.output, s.input)->has_integrator();
}
bool any_column(const Context& cx, const Site& s) { return cx.excited[s.input] && !column_outputs(cx, s.input).empty(); }
// An actuator lag shows as a common lag on two or more channels; on one it is
// that channel's extra lag.
bool shared_column(const Context& cx, const Site& s) { return cx.excited[s.input] && column_outputs(cx, s.input).size() >= 2; }
// With one input, a row form is that channel's own.
bool shared_row(const Context& cx, const Site& s) { return row_prediction(cx, s.output).channels.size() >= 2; }
// A transmitter lag lags the disturbances too, which no channel's own lag
// does: it is told from one even where a single input drives the output.
bool modelled_row(const Context& cx, const Site& s) { return !row_prediction(cx, s.output).channels.empty(); }
// Two or more outputs that several inputs drive (with one, the row form says it).
bool shared_rows(const Context& cx, const Site&) {
  std::size_t n = 0;
  for (std::size_t j = 0; j < cx.n_out(); ++j) n += row_prediction(cx, j).channels.size() >= 2;
  return n >= 2;
}
bool always(const Context&, const Site&) { return true; }
bool known_noise(const Context& cx, const Site& s) {
  return s.output < cx.problem.noise.size() && cx.problem.noise[s.output].has_value();
}

using P = Physics;
using S = Scope;
using G = Gate;

// In generation order within each scope: the order breaks ties between
// candidates of equal selection score.
const std::array<Hypothesis, 17> kTable{{
    {P::gain, S::channel, 1, Per::finding, G::beyond_noise, modelled_channel, fit_gain, say_gain},
    {P::dead_time, S::channel, 1, Per::finding, G::beyond_noise, modelled_channel, fit_dead_time, say_dead_time},
    {P::time_constant, S::channel, 1, Per::finding, G::beyond_noise, slow_mode, fit_time_constant,
     say_time_constant},
    {P::unmodeled_dynamics, S::channel, 1, Per::finding, G::beyond_noise, modelled_channel, fit_extra_lag,
     say_extra_lag},
    // gain and balance input (where an integrating plant holds still)
    {P::integrator, S::channel, 2, Per::finding, G::beyond_noise, self_regulating, fit_integrator, say_integrator},
    // gain, time constant, delay
    {P::missing_channel, S::channel, 3, Per::finding, G::beyond_noise, unmodelled_channel, fit_missing_channel,
     say_missing_channel},
    {P::actuator_dynamics, S::column, 1, Per::finding, G::beyond_noise, shared_column, fit_actuator, say_actuator},
    // one gain factor per channel of the input
    {P::gain, S::column, 1, Per::channel, G::beyond_noise, shared_column, fit_column_gains, say_column_gains},
    {P::saturation, S::column, 1, Per::finding, G::beyond_noise, any_column, fit_saturation, say_saturation},
    {P::deadband, S::column, 1, Per::finding, G::beyond_noise, any_column, fit_deadband, say_deadband},
    // linear, even, odd term per channel, on the column and (of two or more) on
    // each channel; offered only past its nested test against the best linear gains
    {P::nonlinear_gain, S::column, 3, Per::channel, G::beyond_noise, any_column, fit_static_map, say_static_map},
    // a gain set by the output's own level: one slope per output
    {P::nonlinear_gain, S::row, 1, Per::output, G::beyond_noise, shared_row, fit_row_level_gain, say_level_gain},
    // A sensor lag is itself partly a change of what the disturbances look
    // like, so the AR(3) gate would take its own lag of the noise from it;
    // its competitor, the changed disturbance model, stands in the same pool
    // of candidates, and the selection weighs the two on the same score.
    {P::sensor_dynamics, S::row, 1, Per::finding, G::held_out, modelled_row, fit_sensor, say_sensor},
    {P::nonlinear_gain, S::plant, 1, Per::output, G::beyond_noise, shared_rows, fit_plant_level_gain,
     say_level_gain},
    // the signal through each modelled channel of the output (a disturbance entering with that input)
    {P::unmodeled_input, S::signal, 1, Per::finding, G::held_out, always, fit_signal_through_channel,
     say_signal_through_channel},
    // first order plus dead time: gain, time constant, delay
    {P::unmodeled_input, S::signal, 3, Per::finding, G::held_out, always, fit_signal_fopdt, say_signal_fopdt},
    // AR(1..3) or ARMA(1,1) on the whitened residual: the fit chooses the
    // count. A candidate of every round, beside the process changes: under
    // feedback G_M u correlates with a residual whose noise model changed, so
    // a process form can fit it too, and only the comparison of the two on
    // the same score tells which explains the output.
    {P::disturbance_model, S::noise, 0, Per::finding, G::held_out, known_noise, fit_disturbance_model,
     say_disturbance_model},
}};

// The plausibility rules, for every row: a fitted value that no physical
// plant has. A gain factor (the channel's, or the linear term of a static
// map) at or below zero reverses or removes the channel's sign (a heater
// that cools); an integrator against the channel's gain likewise; a lag's
// pole outside [0, 1) is no first-order lag (negative: it rings; at or past
// one: it does not settle); a time or width must be positive and a dead
// time not negative. Empty when plausible. A recorded signal's gain has no
// sign to check: the record does not say which way the signal counts (a
// reflux temperature lowers a purity, a feed flow through a negative channel
// raises it), so its fitted sign is reported, not judged.
std::string implausibility(const Finding& f, const Facts& x) {
  for (const auto& [name, v] : f.parameters) {
    const std::string_view n = name;
    if (n.starts_with("gain_factor") && v <= 0.0)
      return "the fitted " + name + " " + fmt(v) + " reverses the channel's sign";
    if (n.ends_with("_pole") && (v < 0.0 || v >= 1.0))
      return "the fitted " + name + " " + fmt(v) + " is outside [0, 1)";
    if ((n.ends_with("_time_constant") || n == "time_constant_ratio" || n == "backlash_width") && v <= 0.0)
      return "the fitted " + name + " " + fmt(v) + " is not positive";
  }
  if (const auto g = x.find("gain_ratio"); g != x.end() && g->second <= 0.0)
    return "the fitted gain ratio " + fmt(g->second) + " makes the integrator act against the channel's sign";
  if (f.fitted && f.fitted->delay < 0)
    return "the fitted dead time " + std::to_string(f.fitted->delay) + " samples is negative";
  return {};
}

}  // namespace

std::span<const Hypothesis> hypothesis_table() { return kTable; }

void run_scope(const Context& cx, Scope scope, const Site& site, std::vector<Candidate>& out) {
  for (const Hypothesis& h : kTable) {
    if (h.scope != scope || !h.applies(cx, site)) continue;
    const std::size_t first = out.size();
    h.fit(cx, h, site, out);
    for (std::size_t k = first; k < out.size(); ++k) {
      Finding& f = out[k].finding;
      f.summary = h.sentence(cx.problem, f, out[k].facts);
      f.implausible = implausibility(f, out[k].facts);
      if (!f.implausible.empty()) f.summary += " (implausible: " + f.implausible + ")";
    }
  }
}

}  // namespace mpm::diagnosis
