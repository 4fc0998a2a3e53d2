#include "sim/channel_edit.hpp"

#include <cmath>
#include <stdexcept>
#include <vector>

namespace mpm::sim {
namespace {

std::string channel_name(const ChannelEdit& e) { return e.output + " <- " + e.input; }

[[noreturn]] void fail(const ChannelEdit& e, const std::string& what) {
  throw std::invalid_argument("channel " + channel_name(e) + ": " + what);
}

std::vector<double> multiply(const std::vector<double>& a, const std::vector<double>& b) {
  std::vector<double> out(a.size() + b.size() - 1, 0.0);
  for (std::size_t i = 0; i < a.size(); ++i)
    for (std::size_t j = 0; j < b.size(); ++j) out[i + j] += a[i] * b[j];
  return out;
}

// G(f s): the coefficient of s^i scales by f^i (polynomials highest power first).
void scale_time(std::vector<double>& poly, double f) {
  const std::size_t degree = poly.size() - 1;
  for (std::size_t idx = 0; idx < poly.size(); ++idx) poly[idx] *= std::pow(f, static_cast<double>(degree - idx));
}

void apply_continuous_edits(ContinuousTf& g, const ChannelEdit& e) {
  if (e.time_constant_factor != 1.0) {
    scale_time(g.num, e.time_constant_factor);
    scale_time(g.den, e.time_constant_factor);
  }
  if (e.add_integrator) g.den.push_back(0.0);  // den(s) * s
}

// A discrete-only channel: only a first-order lag can have its time constant
// scaled without knowing the continuous form: p' = p^(1/f), gain kept.
void scale_discrete_time_constant(DiscreteTf& tf, const ChannelEdit& e) {
  if (tf.den.size() != 2 || !(-tf.den[1] > 0.0 && -tf.den[1] < 1.0))
    fail(e, "time_constant_factor on a discrete channel needs den = [1, -p] with 0 < p < 1 "
            "(give the channel in continuous form otherwise)");
  const double p = -tf.den[1];
  const double p_new = std::pow(p, 1.0 / e.time_constant_factor);
  for (double& b : tf.num) b *= (1.0 - p_new) / (1.0 - p);
  tf.den[1] = -p_new;
}

void apply_discrete_edits(DiscreteTf& tf, const ChannelEdit& e) {
  for (double& b : tf.num) b *= e.gain_factor;
  if (e.pole_factor != 1.0) {
    double f_power = 1.0;  // den_i * f^i scales every z-root by f
    for (double& a : tf.den) {
      a *= f_power;
      f_power *= e.pole_factor;
    }
  }
  if (e.extra_lag_pole != 0.0) {
    const double p = e.extra_lag_pole;
    for (double& b : tf.num) b *= 1.0 - p;
    tf.den = multiply(tf.den, {1.0, -p});
  }
  tf.delay += e.extra_delay;
}

void validate(const ChannelEdit& e) {
  if (!std::isfinite(e.gain_factor)) fail(e, "gain_factor must be finite");
  if (!(e.pole_factor > 0.0) || !std::isfinite(e.pole_factor)) fail(e, "pole_factor must be > 0");
  if (!(e.time_constant_factor > 0.0) || !std::isfinite(e.time_constant_factor))
    fail(e, "time_constant_factor must be > 0");
  if (e.extra_delay < 0) fail(e, "extra_delay must be >= 0 samples");
  if (!(e.extra_lag_pole >= 0.0 && e.extra_lag_pole < 1.0)) fail(e, "extra_lag_pole must be in [0, 1)");
  if (!(e.soft_saturation >= 0.0) || !std::isfinite(e.soft_saturation)) fail(e, "soft_saturation must be >= 0");
  if (e.replace_continuous && e.replace_discrete) fail(e, "give one replacement form, not both");
}

}  // namespace

bool ChannelEdit::changes_nothing() const {
  return gain_factor == 1.0 && pole_factor == 1.0 && time_constant_factor == 1.0 && extra_delay == 0 &&
         extra_lag_pole == 0.0 && !add_integrator && soft_saturation == 0.0 && !replace_continuous &&
         !replace_discrete;
}

DiscreteTf edited_channel(const ChannelModel* nominal, const ChannelEdit& e, double sample_time) {
  validate(e);
  std::optional<ContinuousTf> continuous = e.replace_continuous;
  DiscreteTf tf;
  if (e.replace_discrete) {
    tf = *e.replace_discrete;
  } else if (!continuous) {
    if (nominal == nullptr) fail(e, "the model has no such channel: the edit must give the plant's channel");
    continuous = nominal->continuous;
    tf = nominal->tf;
  }
  try {
    if (continuous) {
      apply_continuous_edits(*continuous, e);
      tf = discretize_zoh(*continuous, sample_time);
    } else {
      if (e.time_constant_factor != 1.0) scale_discrete_time_constant(tf, e);
      if (e.add_integrator) {
        for (double& b : tf.num) b *= sample_time;
        tf.den = multiply(tf.den, {1.0, -1.0});
      }
    }
    apply_discrete_edits(tf, e);
    tf.normalise();
  } catch (const std::invalid_argument& err) {
    if (std::string(err.what()).rfind("channel ", 0) == 0) throw;
    fail(e, err.what());
  }
  return tf;
}

}  // namespace mpm::sim
