#include "config/plant_entries.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/transfer_function.hpp"

namespace mpm::config::detail {
namespace {

std::string join(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

std::string format_number(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", x);
  return text;
}

bool all_zero(const std::vector<double>& v) {
  return std::all_of(v.begin(), v.end(), [](double x) { return x == 0.0; });
}

std::size_t index_of(const YamlReader& reader, const Field& field,
                     const std::vector<std::string>& names, const std::string& kind) {
  const std::string name = reader.name(field);
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end())
    reader.fail(field, "unknown " + kind + " \"" + name + "\" (the plant's " + kind +
                           "s are: " + join(names) + ")");
  return static_cast<std::size_t>(it - names.begin());
}

int read_delay(const YamlReader& reader, const Field& field, const Limits& limits) {
  if (!field.present()) return 0;
  const int delay = reader.integer(field);
  if (delay < 0 || delay > limits.max_delay_samples)
    reader.fail(field, "expected a delay in 0.." + std::to_string(limits.max_delay_samples) +
                           " samples, got " + std::to_string(delay));
  return delay;
}

// A polynomial's coefficients, its length checked before they are read.
std::vector<double> read_poly(const YamlReader& reader, const Field& field, const Limits& limits) {
  if (field.present() && field.node.IsSequence() && field.node.size() > limits.max_poly_length)
    reader.fail(field, "expected at most " + std::to_string(limits.max_poly_length) +
                           " coefficients, got " + std::to_string(field.node.size()));
  return reader.numbers(field);
}

// num, den (optional, default [1]) and delay (optional, default 0) of a
// discrete entry, normalised to den[0] = 1. Normalising can overflow (den[0]
// = 1e-300): that error names the den key too.
DiscreteTf read_discrete(const YamlReader& reader, const Field& entry, const Limits& limits) {
  DiscreteTf tf;
  const Field num = reader.child(entry, "num");
  tf.num = read_poly(reader, num, limits);
  const Field den = reader.child(entry, "den");
  tf.den = den.present() ? read_poly(reader, den, limits) : std::vector<double>{1.0};
  if (tf.den.front() == 0.0)
    reader.fail(reader.element(den, 0), "den[0] must be nonzero (den is normalised to den[0] = 1)");
  tf.delay = read_delay(reader, reader.child(entry, "delay"), limits);
  tf.normalise();  // den[0] != 0 and every coefficient finite: checked above
  const auto finite = [](const std::vector<double>& v) {
    return std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); });
  };
  if (!finite(tf.num) || !finite(tf.den))
    reader.fail(den.present() ? den : num,
                "cannot normalise to den[0] = 1: a coefficient overflows when divided by den[0]");
  return tf;
}

// Leading zeros of an s-polynomial (highest power first) do not change it.
std::vector<double> strip_leading_zeros(std::vector<double> p) {
  const auto first = std::find_if(p.begin(), p.end(), [](double x) { return x != 0.0; });
  if (first == p.end()) return {0.0};
  p.erase(p.begin(), first);
  return p;
}

ContinuousTf read_continuous(const YamlReader& reader, const Field& field, double ts,
                             const Limits& limits) {
  reader.check_keys(field, {"num", "den", "dead_time"});
  const Field num = reader.child(field, "num");
  const Field den = reader.child(field, "den");
  ContinuousTf g;
  g.num = strip_leading_zeros(read_poly(reader, num, limits));
  g.den = strip_leading_zeros(read_poly(reader, den, limits));
  if (all_zero(g.den)) reader.fail(den, "the denominator must not be zero");
  if (!all_zero(g.num) && g.num.size() > g.den.size())
    reader.fail(num, "improper transfer function: numerator degree " +
                         std::to_string(g.num.size() - 1) + " is above denominator degree " +
                         std::to_string(g.den.size() - 1) + " (a ZOH model must be proper)");
  const Field dead = reader.child(field, "dead_time");
  g.dead_time = dead.present() ? reader.number(dead) : 0.0;
  if (g.dead_time < 0.0)
    reader.fail(dead, "expected a dead time >= 0 seconds, got " + format_number(g.dead_time));
  if (g.dead_time / ts > limits.max_delay_samples)
    reader.fail(dead, "expected a dead time of 0.." + std::to_string(limits.max_delay_samples) +
                          " samples (" + format_number(limits.max_delay_samples * ts) +
                          " s), got " + format_number(g.dead_time) + " s");
  return g;
}

double largest_root(const std::vector<double>& ascending) {
  const auto roots = root_magnitudes(ascending);
  return roots.empty() ? 0.0 : *std::max_element(roots.begin(), roots.end());
}

// Roots this close to the unit circle count as on it (as has_integrator does).
constexpr double kUnitCircleMargin = 1e-9;

void fill_continuous(const YamlReader& reader, const Field& entry, double ts, const Limits& limits,
                     ChannelModel& ch) {
  for (const char* key : {"num", "den", "delay"}) {
    const Field stray = reader.child(entry, key);
    if (stray.present())
      reader.fail(stray,
                  "does not go with 'continuous': give num, den and dead_time inside "
                  "continuous: {...}, or use the discrete form alone");
  }
  const Field field = reader.child(entry, "continuous");
  ContinuousTf g = read_continuous(reader, field, ts, limits);
  ch.explicit_zero = all_zero(g.num);
  if (!ch.explicit_zero) {
    try {
      ch.tf = discretize_zoh(g, ts);
    } catch (const std::invalid_argument& e) {
      reader.fail(field, std::string("cannot discretise: ") + e.what());
    }
    check_model_stable(reader, reader.child(field, "den"), ch.tf);
  }
  ch.continuous = std::move(g);
}

void check_noise_roots(const YamlReader& reader, const Field& entry, const DiscreteTf& tf) {
  const double pole = largest_root(tf.den);
  if (pole >= 1.0 - kUnitCircleMargin)
    reader.fail(reader.child(entry, "den"), "N must be stable: it has a pole of magnitude " +
                                                format_number(pole) +
                                                " on or outside the unit circle");
  const double zero = largest_root(tf.num);
  if (zero >= 1.0 - kUnitCircleMargin)
    reader.fail(reader.child(entry, "num"),
                "N must have a stable inverse: it has a zero of magnitude " + format_number(zero) +
                    " on or outside the unit circle (N is non-minimum-phase)");
}

}  // namespace

// The monitor's residual is y - G u with G run open loop (IMC): for a model
// pole outside the unit circle it grows without bound and every later fit
// sees infinities. Integrators (poles on the circle) are fine.
void check_model_stable(const YamlReader& reader, const Field& den, const DiscreteTf& tf) {
  const double pole = largest_root(tf.den);
  if (pole > 1.0 + kUnitCircleMargin)
    reader.fail(den, "expected a stable or integrating model (poles of magnitude <= 1), got a "
                     "pole of magnitude " + format_number(pole) +
                     ": the residual y - G u of an unstable model grows without bound");
}

ChannelModel read_channel(const YamlReader& reader, const Field& entry, const PlantModel& plant,
                          const Limits& limits) {
  reader.check_keys(entry, {"output", "input", "num", "den", "delay", "continuous"});
  ChannelModel ch;
  ch.output = index_of(reader, reader.child(entry, "output"), plant.outputs, "output");
  ch.input = index_of(reader, reader.child(entry, "input"), plant.inputs, "input");
  if (reader.child(entry, "continuous").present()) {
    fill_continuous(reader, entry, plant.sample_time, limits, ch);
    return ch;
  }
  DiscreteTf tf = read_discrete(reader, entry, limits);
  ch.explicit_zero = all_zero(tf.num);
  if (!ch.explicit_zero) {
    const Field den = reader.child(entry, "den");
    if (den.present()) check_model_stable(reader, den, tf);
    ch.tf = std::move(tf);
  }
  return ch;
}

NoiseEntry read_noise(const YamlReader& reader, const Field& entry, const PlantModel& plant,
                      const Limits& limits) {
  reader.check_keys(entry, {"output", "num", "den", "delay", "variance"});
  NoiseEntry out;
  out.output = index_of(reader, reader.child(entry, "output"), plant.outputs, "output");
  DiscreteTf tf = read_discrete(reader, entry, limits);
  if (tf.delay != 0)
    reader.fail(reader.child(entry, "delay"),
                "must be 0: a delayed disturbance model N has no causal inverse");
  if (tf.num.front() == 0.0)
    reader.fail(reader.element(reader.child(entry, "num"), 0),
                "num[0] must be nonzero: N must be invertible (its inverse is den/num)");
  check_noise_roots(reader, entry, tf);
  out.model.tf = std::move(tf);
  const Field variance = reader.child(entry, "variance");
  if (variance.present()) {
    const double v = reader.number(variance);
    if (v <= 0.0) reader.fail(variance, "expected a variance > 0, got " + format_number(v));
    out.model.variance = v;
  }
  return out;
}

}  // namespace mpm::config::detail
