#include "daemon/plant_writer.hpp"

#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "config/json_text.hpp"
#include "config/output_file.hpp"
#include "core/diagnosis_signal.hpp"

namespace mpm {
namespace {

std::string num(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.10g", v);
  return b;
}

std::string short_num(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.4g", v);
  return b;
}

// A YAML flow sequence of numbers reads as the JSON list.
std::string list(const std::vector<double>& v) { return config::json_number_list(v, 10); }

// A YAML scalar: plain where that is unambiguous, double-quoted otherwise.
std::string scalar(const std::string& s) {
  bool plain = !s.empty();
  for (char c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.')) plain = false;
  if (plain && (s == "true" || s == "false" || s == "null" || s == "yes" || s == "no" || s == "~")) plain = false;
  if (plain && (std::isdigit(static_cast<unsigned char>(s[0])) || s[0] == '-' || s[0] == '.')) plain = false;
  if (plain) return s;
  std::string o = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    if (static_cast<unsigned char>(c) < 0x20) {
      char b[8];
      std::snprintf(b, sizeof b, "\\x%02x", static_cast<unsigned>(c));
      o += b;
      continue;
    }
    o += c;
  }
  return o + "\"";
}

std::string names(const std::vector<std::string>& v) {
  std::string o = "[";
  for (std::size_t k = 0; k < v.size(); ++k) o += (k ? ", " : "") + scalar(v[k]);
  return o + "]";
}

// One comment line per finding: what, and the numbers that justified it.
std::string reason(const diagnosis::Finding& f) {
  const double hb = f.fit.holdout_variance_before, ha = f.fit.holdout_variance_after;
  std::string r = f.physics + ": " + f.summary;
  if (hb > 0.0 && std::isfinite(hb) && std::isfinite(ha))
    r += "; held-out prediction-error variance " + short_num(hb) + " -> " + short_num(ha) + " (" +
         num(std::round(1000.0 * (1.0 - ha / hb)) / 10.0) + " % less)";
  r += "; likelihood ratio " + num(std::round(10.0 * f.lr) / 10.0) + " on " + std::to_string(f.params) +
       " parameter" + (f.params == 1 ? "" : "s");
  return r;
}

std::string describe(const DiscreteTf& tf) {
  return "num " + list(tf.num) + ", den " + list(tf.den) + ", delay " + std::to_string(tf.delay);
}

// The input file's entry, for the comment above a changed one.
std::string was(const ChannelModel& m) {
  if (m.tf.is_zero()) return "was: no channel (zero gain)";
  if (m.continuous)
    return "was: continuous num " + list(m.continuous->num) + ", den " + list(m.continuous->den) + ", dead_time " +
           num(m.continuous->dead_time);
  return "was: " + describe(m.tf);
}

double param(const diagnosis::Finding& f, const char* key, double fallback) {
  const auto it = f.parameters.find(key);
  return it == f.parameters.end() ? fallback : it->second;
}

using diagnosis::Physics;
bool is(const diagnosis::Finding& f, Physics p) { return f.physics == diagnosis::word(p); }

// Findings on one channel whose fitted model replaces (or changes) that channel.
bool is_channel_physics(const diagnosis::Finding& f) {
  for (Physics p : {Physics::gain, Physics::dead_time, Physics::time_constant, Physics::unmodeled_dynamics,
                    Physics::integrator, Physics::missing_channel})
    if (is(f, p)) return true;
  return false;
}

// Index into plant.channels of (output, input), added (zero) when absent.
std::size_t channel_index(CorrectedPlant& c, std::size_t output, std::size_t input) {
  for (std::size_t k = 0; k < c.plant.channels.size(); ++k)
    if (c.plant.channels[k].output == output && c.plant.channels[k].input == input) return k;
  ChannelModel m;
  m.output = output;
  m.input = input;
  c.plant.channels.push_back(m);
  c.why.emplace_back();
  return c.plant.channels.size() - 1;
}

void apply_channel(CorrectedPlant& c, const diagnosis::Finding& f, const diagnosis::Channel& ch) {
  const std::size_t k = channel_index(c, ch.output, *ch.input);
  ChannelModel& m = c.plant.channels[k];
  const bool first = c.why[k].empty();
  if (first) c.why[k].push_back(was(m));
  if (is(f, Physics::gain)) {
    // One factor per channel where the finding spans a column (gain_factor_<output>).
    const std::string key =
        f.channels.size() == 1 ? std::string("gain_factor") : "gain_factor_" + c.plant.outputs[ch.output];
    const double g = param(f, key.c_str(), 1.0);
    for (double& b : m.tf.num) b *= g;
    if (m.continuous)
      for (double& b : m.continuous->num) b *= g;
  } else if (is(f, Physics::dead_time)) {
    const int s = static_cast<int>(std::lround(param(f, "extra_delay_samples", 0.0)));
    m.tf.delay += s;
    if (m.continuous) m.continuous->dead_time += s * c.plant.sample_time;
  } else if (is(f, Physics::unmodeled_dynamics) && f.parameters.count("extra_lag_pole")) {
    m.tf = diagnosis::series(m.tf, diagnosis::unit_lag(param(f, "extra_lag_pole", 0.0)));
    m.continuous.reset();
  } else {
    // time_constant, integrator, missing_channel: the fitted model itself.
    m.tf = *f.fitted;
    m.continuous.reset();
    if (!first) c.why[k].push_back("(the fitted model below replaces the change above: it was fitted against the nominal channel)");
  }
  m.explicit_zero = false;
  c.why[k].push_back(reason(f));
}

void apply_series_lag(CorrectedPlant& c, const diagnosis::Finding& f, double pole) {
  for (const auto& ch : f.channels) {
    if (!ch.input) continue;
    const std::size_t k = channel_index(c, ch.output, *ch.input);
    ChannelModel& m = c.plant.channels[k];
    if (c.why[k].empty()) c.why[k].push_back(was(m));
    m.tf = diagnosis::series(m.tf, diagnosis::unit_lag(pole));
    m.continuous.reset();
    c.why[k].push_back(reason(f));
  }
}

}  // namespace

CorrectedPlant apply_findings(const PlantModel& plant, const diagnosis::Result& result) {
  CorrectedPlant c;
  c.plant = plant;
  c.why.assign(plant.channels.size(), {});
  c.noise_why.assign(plant.n_outputs(), {});
  for (const diagnosis::Finding& f : result.findings) {
    if (!f.implausible.empty()) {
      c.held_back.push_back(reason(f));
      c.written.push_back(Written::kImplausible);
      continue;
    }
    const bool one_channel = f.channels.size() == 1 && f.channels[0].input.has_value();
    if (is_channel_physics(f) && one_channel && f.fitted) {
      apply_channel(c, f, f.channels[0]);
    } else if (is(f, Physics::gain) && f.fitted) {
      for (const auto& ch : f.channels)
        if (ch.input) apply_channel(c, f, ch);
    } else if (is(f, Physics::actuator_dynamics) && f.parameters.count("actuator_lag_pole")) {
      apply_series_lag(c, f, f.parameters.at("actuator_lag_pole"));
    } else if (is(f, Physics::sensor_dynamics) && f.parameters.count("sensor_lag_pole")) {
      apply_series_lag(c, f, f.parameters.at("sensor_lag_pole"));
    } else if (is(f, Physics::disturbance_model) && f.fitted && f.channels.size() == 1) {
      const std::size_t j = f.channels[0].output;
      NoiseModel n;
      n.tf = *f.fitted;
      n.tf.normalise();
      if (f.parameters.count("variance")) n.variance = f.parameters.at("variance");
      c.plant.noise[j] = n;
      c.noise_why[j].push_back(reason(f));
    } else {
      c.not_applied.push_back(reason(f));
      c.written.push_back(Written::kNotExpressible);
      continue;
    }
    c.written.push_back(Written::kApplied);
    ++c.changes;
  }
  return c;
}

std::string plant_yaml(const CorrectedPlant& c, const std::string& source_plant, const std::string& source_data) {
  const PlantModel& p = c.plant;
  std::string o;
  o += "# Written by `mpm diagnose --write-plant` from the plant file\n#   " + source_plant +
       "\n# and the recording\n#   " + source_data + "\n";
  if (c.changes == 0) o += "# No correction was accepted: the model is the input's.\n";
  else
    o += "# " + std::to_string(c.changes) +
         " accepted correction(s) applied; each changed entry says why just above it.\n"
         "# Changed channels are written in discrete form (polynomials in q^-1) unless the\n"
         "# change is exact in continuous form too.\n";
  for (const std::string& s : c.not_applied)
    o += "# NOT applied (the plant format cannot express it): " + s + "\n";
  for (const std::string& s : c.held_back)
    o += "# NOT applied (implausible: judge it before using it): " + s + "\n";
  o += "plant: " + scalar(p.name.empty() ? std::string("corrected") : p.name) + "\n";
  o += "sample_time: " + num(p.sample_time) + "\n";
  o += "inputs: " + names(p.inputs) + "\n";
  o += "outputs: " + names(p.outputs) + "\n\nmodel:\n";
  for (std::size_t k = 0; k < p.channels.size(); ++k) {
    const ChannelModel& m = p.channels[k];
    if (!c.why[k].empty()) {
      o += "  # CHANGED by mpm diagnose:\n";
      for (const std::string& w : c.why[k]) o += "  #   " + w + "\n";
    }
    o += "  - output: " + scalar(p.outputs[m.output]) + "\n    input: " + scalar(p.inputs[m.input]) + "\n";
    if (m.continuous) {
      o += "    continuous: {num: " + list(m.continuous->num) + ", den: " + list(m.continuous->den) +
           ", dead_time: " + num(m.continuous->dead_time) + "}\n";
    } else {
      o += "    num: " + list(m.explicit_zero ? std::vector<double>{0.0} : m.tf.num) + "\n    den: " + list(m.tf.den) +
           "\n    delay: " + std::to_string(m.tf.delay) + "\n";
    }
  }
  bool any_noise = false;
  for (const auto& n : p.noise) any_noise = any_noise || n.has_value();
  if (any_noise) {
    o += "\nnoise:\n";
    for (std::size_t j = 0; j < p.noise.size(); ++j) {
      if (!p.noise[j]) continue;
      if (!c.noise_why[j].empty()) {
        o += "  # CHANGED by mpm diagnose:\n";
        for (const std::string& w : c.noise_why[j]) o += "  #   " + w + "\n";
      }
      const NoiseModel& n = *p.noise[j];
      o += "  - output: " + scalar(p.outputs[j]) + "\n    num: " + list(n.tf.num) + "\n    den: " + list(n.tf.den) + "\n";
      if (n.variance) o += "    variance: " + num(*n.variance) + "\n";
    }
  }
  if (p.operating_point) {
    o += "\noperating_point:\n  inputs: " + list(p.operating_point->inputs) +
         "\n  outputs: " + list(p.operating_point->outputs) + "\n";
  }
  return o;
}

void write_text_file(const std::string& path, const std::string& text, const std::vector<std::string>& protected_paths) {
  config::refuse_input_as_output(path, protected_paths);
  config::write_output_file(path, text);
}

}  // namespace mpm
