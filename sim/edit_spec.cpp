#include "sim/edit_spec.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <map>
#include <optional>
#include <stdexcept>
#include <tuple>

namespace mpm::sim {
namespace {

enum class Range { finite, positive, unit_interval, samples, flag, at_most_zero, at_least_zero, non_negative };

struct Key {
  std::string_view name;
  EditField field;
  Range range;
};

constexpr Key kKeys[] = {
    {"gain", EditField::gain, Range::finite},
    {"pole", EditField::pole, Range::positive},
    {"time_constant", EditField::time_constant, Range::positive},
    {"delay", EditField::delay, Range::samples},
    {"lag", EditField::lag, Range::unit_interval},
    {"integrator", EditField::integrator, Range::flag},
    {"soft_saturation", EditField::soft_saturation, Range::non_negative},
    {"actuator_lag", EditField::actuator_lag, Range::unit_interval},
    {"lower", EditField::lower, Range::at_most_zero},
    {"upper", EditField::upper, Range::at_least_zero},
    {"deadband", EditField::deadband, Range::non_negative},
    {"sensor_lag", EditField::sensor_lag, Range::unit_interval},
};

const char* kForms = "expected OUTPUT.INPUT.KEY=VALUE, INPUT.KEY=VALUE or OUTPUT.KEY=VALUE";

[[noreturn]] void fail(std::string_view text, const std::string& what) {
  throw std::invalid_argument("'" + std::string(text) + "': " + what);
}

std::string join(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

std::string keys_of(EditTarget target) {
  std::string out;
  for (const Key& k : kKeys)
    if (target_of(k.field) == target) out += (out.empty() ? "" : ", ") + std::string(k.name);
  return out;
}

bool contains(const std::vector<std::string>& names, std::string_view name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

// Whole-string decimal number (a leading '+' allowed); nullopt otherwise.
// Too large a magnitude reads as +-inf (refused later as non-finite).
std::optional<double> to_number(std::string_view s) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  double x = 0.0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), x);
  if (s.empty() || end != s.data() + s.size()) return std::nullopt;
  if (ec == std::errc::result_out_of_range) return std::strtod(std::string(s).c_str(), nullptr);
  if (ec != std::errc()) return std::nullopt;
  return x;
}

// Empty when x is in range, else what the range is.
std::string range_problem(Range range, double x) {
  switch (range) {
    case Range::finite: return "";
    case Range::positive: return x > 0.0 ? "" : "must be > 0";
    case Range::unit_interval: return x >= 0.0 && x < 1.0 ? "" : "must be in [0, 1)";
    case Range::samples:
      return x >= 0.0 && x <= kMaxEditDelay && x == std::floor(x)
                 ? ""
                 : "must be a whole number of samples from 0 to " + std::to_string(kMaxEditDelay);
    case Range::flag: return x == 0.0 || x == 1.0 ? "" : "must be 1 (or 0), or have no value";
    case Range::at_most_zero: return x <= 0.0 ? "" : "must be <= 0 (deviation from the operating point)";
    case Range::at_least_zero: return x >= 0.0 ? "" : "must be >= 0 (deviation from the operating point)";
    case Range::non_negative: return x >= 0.0 ? "" : "must be >= 0";
  }
  return "";
}

// target = OUTPUT.INPUT; names may themselves hold dots, so every split is tried.
void resolve_channel(std::string_view text, std::string_view target, const std::vector<std::string>& inputs,
                     const std::vector<std::string>& outputs, EditSpec& spec) {
  for (std::size_t dot = target.find('.'); dot != std::string_view::npos; dot = target.find('.', dot + 1)) {
    if (contains(outputs, target.substr(0, dot)) && contains(inputs, target.substr(dot + 1))) {
      spec.output = std::string(target.substr(0, dot));
      spec.input = std::string(target.substr(dot + 1));
      return;
    }
  }
  const std::size_t dot = target.find('.');
  if (dot == std::string_view::npos) fail(text, "a channel key needs OUTPUT.INPUT before it");
  if (!contains(outputs, target.substr(0, dot)))
    fail(text, "unknown output '" + std::string(target.substr(0, dot)) + "' (outputs: " + join(outputs) + ")");
  fail(text, "unknown input '" + std::string(target.substr(dot + 1)) + "' (inputs: " + join(inputs) + ")");
}

void set_field(const EditSpec& s, ChannelEdit& e) {
  switch (s.field) {
    case EditField::gain: e.gain_factor = s.value; break;
    case EditField::pole: e.pole_factor = s.value; break;
    case EditField::time_constant: e.time_constant_factor = s.value; break;
    case EditField::delay: e.extra_delay = static_cast<int>(s.value); break;
    case EditField::lag: e.extra_lag_pole = s.value; break;
    case EditField::integrator: e.add_integrator = s.value != 0.0; break;
    case EditField::soft_saturation: e.soft_saturation = s.value; break;
    default: break;
  }
}

void set_field(const EditSpec& s, InputEdit& e) {
  switch (s.field) {
    case EditField::actuator_lag: e.actuator_lag_pole = s.value; break;
    case EditField::lower: e.lower_limit = s.value; break;
    case EditField::upper: e.upper_limit = s.value; break;
    case EditField::deadband: e.deadband_width = s.value; break;
    default: break;
  }
}

// The plant's edit for `match`, added (named by `init`) when there is none.
template <class Edit, class Match, class Init>
Edit& edit_for(std::vector<Edit>& edits, Match match, Init init) {
  const auto it = std::find_if(edits.begin(), edits.end(), match);
  if (it != edits.end()) return *it;
  edits.emplace_back();
  init(edits.back());
  return edits.back();
}

}  // namespace

EditTarget target_of(EditField field) {
  switch (field) {
    case EditField::actuator_lag:
    case EditField::lower:
    case EditField::upper:
    case EditField::deadband: return EditTarget::input;
    case EditField::sensor_lag: return EditTarget::output;
    default: return EditTarget::channel;
  }
}

EditSpec parse_edit(std::string_view text, const std::vector<std::string>& inputs,
                    const std::vector<std::string>& outputs) {
  EditSpec spec;
  spec.text = std::string(text);
  const std::size_t eq = text.find('=');
  const std::string_view lhs = text.substr(0, eq);
  const std::size_t dot = lhs.rfind('.');
  if (dot == std::string_view::npos || dot == 0) fail(text, kForms);
  const std::string_view key_name = lhs.substr(dot + 1), target = lhs.substr(0, dot);
  const auto key = std::find_if(std::begin(kKeys), std::end(kKeys), [&](const Key& k) { return k.name == key_name; });
  if (key == std::end(kKeys))
    fail(text, "unknown key '" + std::string(key_name) + "' (channel OUTPUT.INPUT.KEY: " +
                   keys_of(EditTarget::channel) + "; input INPUT.KEY: " + keys_of(EditTarget::input) +
                   "; output OUTPUT.KEY: " + keys_of(EditTarget::output) + ")");
  spec.field = key->field;

  switch (target_of(key->field)) {
    case EditTarget::channel: resolve_channel(text, target, inputs, outputs, spec); break;
    case EditTarget::input:
      if (!contains(inputs, target))
        fail(text, "unknown input '" + std::string(target) + "' (inputs: " + join(inputs) + ")");
      spec.input = std::string(target);
      break;
    case EditTarget::output:
      if (!contains(outputs, target))
        fail(text, "unknown output '" + std::string(target) + "' (outputs: " + join(outputs) + ")");
      spec.output = std::string(target);
      break;
  }

  if (eq == std::string_view::npos) {
    if (key->field != EditField::integrator) fail(text, std::string(key->name) + " needs a value (KEY=VALUE)");
    spec.value = 1.0;
    return spec;
  }
  const std::string_view value_text = text.substr(eq + 1);
  const std::optional<double> value = to_number(value_text);
  if (!value) fail(text, "expected a number after '=', got '" + std::string(value_text) + "'");
  if (!std::isfinite(*value)) fail(text, std::string(key->name) + " must be a finite number");
  if (const std::string problem = range_problem(key->range, *value); !problem.empty())
    fail(text, std::string(key->name) + " " + problem);
  spec.value = *value;
  return spec;
}

void apply_edits(const std::vector<EditSpec>& specs, PlantSpec& plant) {
  // (target kind, output, input, field) -> the spec that set it
  std::map<std::tuple<EditTarget, std::string, std::string, EditField>, const EditSpec*> given;
  std::map<std::string, const EditSpec*> last_input_spec;
  for (const EditSpec& s : specs) {
    const EditTarget target = target_of(s.field);
    const auto [it, fresh] = given.emplace(std::make_tuple(target, s.output, s.input, s.field), &s);
    if (!fresh) fail(s.text, "the same key is already given by '" + it->second->text + "'");
    switch (target) {
      case EditTarget::channel: {
        if (plant.kind == ProcessKind::quad_tank)
          fail(s.text, "the nonlinear quadruple tank takes no channel edits (edit its inputs or outputs)");
        set_field(s, edit_for(
                         plant.channels, [&](const ChannelEdit& e) { return e.output == s.output && e.input == s.input; },
                         [&](ChannelEdit& e) {
                           e.output = s.output;
                           e.input = s.input;
                         }));
        break;
      }
      case EditTarget::input:
        set_field(s, edit_for(
                         plant.inputs, [&](const InputEdit& e) { return e.input == s.input; },
                         [&](InputEdit& e) { e.input = s.input; }));
        last_input_spec[s.input] = &s;
        break;
      case EditTarget::output:
        edit_for(
            plant.outputs, [&](const OutputEdit& e) { return e.output == s.output; },
            [&](OutputEdit& e) { e.output = s.output; })
            .sensor_lag_pole = s.value;
        break;
    }
  }
  // Per key the ranges are checked already; what is left is lower vs upper.
  for (const InputEdit& e : plant.inputs) {
    const auto it = last_input_spec.find(e.input);
    if (it == last_input_spec.end()) continue;
    try {
      validate(e);
    } catch (const std::invalid_argument& err) {
      fail(it->second->text, err.what());
    }
  }
}

std::string describe(const std::vector<EditSpec>& specs) {
  std::string out;
  for (const auto& s : specs) out += (out.empty() ? "" : ", ") + s.text;
  return out;
}

}  // namespace mpm::sim
