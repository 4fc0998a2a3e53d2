// The sentence of each hypothesis row (the finding's `summary`), from the
// finding and the facts its fit left: no fitting here, and no sentence in
// the fit functions.
#include <string>

#include "core/diagnosis_table.hpp"

namespace mpm::diagnosis {
namespace {

std::string arrow(const Problem& p, std::size_t j, std::size_t i) { return p.inputs[i] + " -> " + p.outputs[j]; }
// The finding's one channel.
std::string arrow(const Problem& p, const Finding& f) { return arrow(p, f.channels[0].output, *f.channels[0].input); }
double param(const Finding& f, const std::string& name) { return f.parameters.at(name); }
double fact(const Facts& x, const std::string& name) { return x.at(name); }
// Seconds of a lag with this discrete pole.
double lag_seconds(const Problem& p, double pole) { return tau_of(pole) * p.sample_time; }

}  // namespace

std::string say_gain(const Problem& p, const Finding& f, const Facts& x) {
  const double k = param(f, "gain_factor"), se = fact(x, "gain_factor_se");
  return "gain of " + arrow(p, f) + " is " + fmt(k) + " x nominal (95% CI " + fmt(k - 1.96 * se) + "-" +
         fmt(k + 1.96 * se) + ")";
}

std::string say_column_gains(const Problem& p, const Finding& f, const Facts& x) {
  std::string m = "gains of " + p.inputs[*f.channels[0].input] + " changed:";
  for (std::size_t r = 0; r < f.channels.size(); ++r) {
    const std::string& out = p.outputs[f.channels[r].output];
    const double k = param(f, "gain_factor_" + out), se = fact(x, "gain_factor_se_" + out);
    m += std::string(r ? "," : "") + " -> " + out + " " + fmt(k) + " x nominal (95% CI " + fmt(k - 1.96 * se) + "-" +
         fmt(k + 1.96 * se) + ")";
  }
  return m;
}

std::string say_dead_time(const Problem& p, const Finding& f, const Facts&) {
  return "dead time of " + arrow(p, f) + " is " + std::to_string(f.fitted->delay) + " samples (" +
         fmt(f.fitted->delay * p.sample_time) + " s), nominal " + std::to_string(f.nominal->delay);
}

std::string say_time_constant(const Problem& p, const Finding& f, const Facts& x) {
  const double ratio = param(f, "time_constant_ratio"), tau = fact(x, "nominal_time_constant_samples");
  return "dominant time constant of " + arrow(p, f) + " is " + fmt(ratio) + " x nominal (" +
         fmt(tau * ratio * p.sample_time) + " s vs " + fmt(tau * p.sample_time) + " s), gain kept";
}

std::string say_extra_lag(const Problem& p, const Finding& f, const Facts&) {
  const double a = param(f, "extra_lag_pole");
  return arrow(p, f) + " has an extra lag of " + fmt(lag_seconds(p, a)) + " s (pole " + fmt(a) + ") the model lacks";
}

std::string say_integrator(const Problem& p, const Finding& f, const Facts& x) {
  const auto replaced = x.find("replaced_pole");
  return arrow(p, f) + " integrates: " +
         (replaced != x.end() ? "slowest pole " + fmt(replaced->second) + " -> 1"
                              : std::string("an integrator after the channel")) +
         ", gain x " + fmt(fact(x, "gain_ratio")) + ", holding still at " + p.inputs[*f.channels[0].input] + " " +
         fmt(param(f, "balance_input_offset")) + " from the model's operating point";
}

std::string say_missing_channel(const Problem& p, const Finding& f, const Facts& x) {
  return "the model has no " + arrow(p, f) + " channel; the plant responds with gain " + fmt(fact(x, "gain")) +
         ", time constant " + fmt(lag_seconds(p, fact(x, "pole"))) + " s, delay " + std::to_string(f.fitted->delay) +
         " samples";
}

std::string say_actuator(const Problem& p, const Finding& f, const Facts&) {
  const double a = param(f, "actuator_lag_pole");
  return "actuator of " + p.inputs[*f.channels[0].input] + " lags with time constant " + fmt(lag_seconds(p, a)) +
         " s (pole " + fmt(a) + ") on every channel";
}

std::string say_saturation(const Problem& p, const Finding& f, const Facts&) {
  const bool upper = f.parameters.count("upper_limit") > 0;
  return p.inputs[*f.channels[0].input] + " stops acting " + (upper ? "above " : "below ") +
         fmt(param(f, upper ? "upper_limit" : "lower_limit"), 4) + " (the model knows no limit there)";
}

std::string say_deadband(const Problem& p, const Finding& f, const Facts&) {
  return p.inputs[*f.channels[0].input] + " has a backlash (deadband) of total width " +
         fmt(param(f, "backlash_width")) + ": reversals smaller than that do nothing";
}

std::string say_static_map(const Problem& p, const Finding& f, const Facts& x) {
  const std::string& input = p.inputs[*f.channels[0].input];
  std::string terms;
  for (std::size_t r = 0; r < f.channels.size(); ++r) {
    const std::string& out = p.outputs[f.channels[r].output];
    const std::string suffix = f.channels.size() == 1 ? std::string() : "_" + out;
    terms += (r ? "; " : "") + out + ": gain x " + fmt(param(f, "gain_factor" + suffix)) + ", even " +
             fmt(param(f, "even_coefficient" + suffix)) + ", odd " + fmt(param(f, "odd_coefficient" + suffix));
  }
  return "gain of " + input + " changes with its level around " + fmt(fact(x, "working_level"), 4) + " (" + terms +
         " per unit^2 of " + input + ")";
}

std::string say_level_gain(const Problem& p, const Finding& f, const Facts&) {
  // The finding's outputs, in the order of its channels (each row's together).
  std::vector<std::size_t> js;
  for (const Channel& c : f.channels)
    if (js.empty() || js.back() != c.output) js.push_back(c.output);
  std::string slopes;
  for (std::size_t r = 0; r < js.size(); ++r) {
    const std::string& name = p.outputs[js[r]];
    slopes += (r ? ", " : "") + fmt(param(f, "gain_slope_per_unit_" + name)) + " per unit of " + name;
  }
  return "gain of every input into " + (js.size() == 1 ? p.outputs[js[0]] : std::string("each output")) +
         " changes with that output's level (relative slope " + slopes + ")";
}

std::string say_sensor(const Problem& p, const Finding& f, const Facts&) {
  const double a = param(f, "sensor_lag_pole");
  return "sensor of " + p.outputs[f.channels[0].output] + " lags with time constant " + fmt(lag_seconds(p, a)) +
         " s (pole " + fmt(a) + ")";
}

std::string say_signal_through_channel(const Problem& p, const Finding& f, const Facts& x) {
  const auto i = static_cast<std::size_t>(fact(x, "through_input"));
  return "recorded signal " + *f.signal + " drives " + p.outputs[f.channels[0].output] + ": it acts like " +
         p.inputs[i] + " (through its channel, x " + fmt(fact(x, "factor")) + ")";
}

std::string say_signal_fopdt(const Problem& p, const Finding& f, const Facts& x) {
  return "recorded signal " + *f.signal + " drives " + p.outputs[f.channels[0].output] + " through gain " +
         fmt(fact(x, "gain")) + ", time constant " + fmt(lag_seconds(p, fact(x, "pole"))) + " s, delay " +
         std::to_string(f.fitted->delay) + " samples";
}

std::string say_disturbance_model(const Problem& p, const Finding& f, const Facts& x) {
  return "no input or recorded signal explains " + p.outputs[f.channels[0].output] +
         "'s residual, but its one-step prediction error is " +
         fmt(100.0 * (1.0 - param(f, "variance") / fact(x, "variance_before")), 2) +
         " % smaller with a changed disturbance model (" +
         (fact(x, "arma") != 0.0 ? std::string("ARMA(1,1)") : "AR order " + std::to_string(f.params)) +
         " on N^-1 d)";
}

std::string say_other(const Problem& p, const Finding& f) {
  return "the Granger test locates a mismatch in " + p.outputs[f.channels[0].output] +
         " that none of the structured hypotheses explains significantly";
}

}  // namespace mpm::diagnosis
