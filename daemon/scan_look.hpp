// One look of the live diagnosis scan (core/diagnosis_scan.hpp) and the
// words of a finding, shared by `mpm monitor --events` (run at once) and
// mpmd (run on its diagnosis thread), so that both report the same finding
// with the same numbers: the offline diagnosis (what `mpm diagnose` runs)
// over a window of samples at the scan's per-look level.
#pragma once

#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "core/diagnosis.hpp"
#include "core/plant_model.hpp"
#include "daemon/offline.hpp"
#include "transport/messages.hpp"

namespace mpm {

// A JSON string: quotes and backslashes escaped, control characters as
// spaces (a finding's text has none but newlines at worst).
inline std::string json_quoted(const std::string& s) {
  std::string o = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    o += static_cast<unsigned char>(c) < 0x20 ? ' ' : c;
  }
  return o + "\"";
}

// The diagnosis of a window: u (samples x inputs, absolute), residual
// (samples x outputs, NaN = missing or not evidence) at family level alpha,
// with no monitor verdict (the scan stands on the diagnosis' own test).
inline diagnosis::Result diagnose_window(const PlantModel& plant, const std::vector<std::optional<DiscreteTf>>& nominal,
                                         const Eigen::MatrixXd& u, const Eigen::MatrixXd& residual, double alpha,
                                         const std::vector<bool>& monitor_flag = {},
                                         const std::vector<std::vector<std::size_t>>& monitor_located = {}) {
  diagnosis::Problem problem = plant_problem(plant, u, residual);
  problem.nominal = nominal;  // computed once, at setup
  problem.monitor_flag = monitor_flag;
  problem.monitor_located = monitor_located;
  diagnosis::Settings settings;
  settings.alpha = alpha;
  return diagnosis::diagnose(problem, settings);
}

// The finding that explains an output best: one on `input` when given, else
// the first accepted (the best) on the output, else none.
inline const diagnosis::Finding* finding_for(const diagnosis::Result& result, std::size_t output,
                                             std::optional<std::size_t> input = std::nullopt) {
  const diagnosis::Finding* on_output = nullptr;
  for (const auto& f : result.findings) {
    for (const auto& c : f.channels) {
      if (c.output != output) continue;
      if (input && c.input && *c.input == *input) return &f;
      if (on_output == nullptr) on_output = &f;
    }
  }
  return on_output;
}

// Per output: whether an accepted finding names it.
inline std::vector<bool> flagged_outputs(const diagnosis::Result& result, std::size_t outputs) {
  std::vector<bool> flagged(outputs, false);
  for (const auto& f : result.findings)
    for (const auto& c : f.channels)
      if (c.output < outputs) flagged[c.output] = true;
  return flagged;
}

// The finding's input on `output` (the channel a raise names), if any.
inline std::optional<std::size_t> finding_input(const diagnosis::Finding& f, std::size_t output) {
  for (const auto& c : f.channels)
    if (c.output == output && c.input) return c.input;
  return std::nullopt;
}

// Physics word, channels, fitted parameters, held-out improvement and text
// of a finding into a diagnosis message (its header is the caller's).
inline void describe_finding(const PlantModel& plant, const diagnosis::Finding& f, msg::Diagnosis& d) {
  d.found = true;
  d.physics = f.physics;
  d.channels.clear();
  for (std::size_t c = 0; c < f.channels.size(); ++c) {
    const auto& ch = f.channels[c];
    d.channels += (c ? ", " : "") + (ch.input ? plant.inputs[*ch.input] : std::string("(no input)")) + " -> " +
                  plant.outputs[ch.output];
  }
  d.parameter_names.clear();
  d.parameter_values.clear();
  if (f.nominal && f.fitted) {
    const double g0 = f.nominal->dc_gain(), g1 = f.fitted->dc_gain();
    if (std::isfinite(g0) && std::isfinite(g1) && g0 != 0.0) {
      d.parameter_names.push_back("gain_ratio");
      d.parameter_values.push_back(g1 / g0);
    }
    d.parameter_names.push_back("delay_change");
    d.parameter_values.push_back(f.fitted->delay - f.nominal->delay);
  }
  for (const auto& [name, value] : f.parameters) {
    d.parameter_names.push_back(name);
    d.parameter_values.push_back(value);
  }
  const double before = f.fit.holdout_variance_before, after = f.fit.holdout_variance_after;
  d.holdout_improvement = before > 0.0 ? 1.0 - after / before : 0.0;
  char tail[96];
  std::snprintf(tail, sizeof tail, " (held-out prediction error %.1f %% lower)", 100.0 * d.holdout_improvement);
  d.text = f.summary + tail;
}

}  // namespace mpm
