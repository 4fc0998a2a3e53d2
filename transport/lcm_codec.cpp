#include "transport/lcm_codec.hpp"

#include <algorithm>

namespace mpm::transport::lcm_codec {

namespace {

template <typename T>
std::int32_t length(const std::vector<T>& v) {
  return static_cast<std::int32_t>(v.size());
}

template <typename T>
bool has_length(const std::vector<T>& v, std::int32_t n) {
  return n >= 0 && v.size() == static_cast<std::size_t>(n);
}

// Our message structs and the generated LCM types use the same field names:
// one copy per message kind serves both directions.
template <typename From, typename To>
void copy_channel(const From& in, To& out) {
  out.output = in.output;
  out.input = in.input;
  out.f_pairwise = in.f_pairwise;
  out.f_conditional = in.f_conditional;
  out.lr = in.lr;
  out.p_value = in.p_value;
  out.gamma = in.gamma;
  out.alarm = in.alarm;
}

template <typename From, typename To>
void copy_loop(const From& in, To& out) {
  out.output = in.output;
  out.residual_variance = in.residual_variance;
  out.sigma1 = in.sigma1;
  out.sigma_full = in.sigma_full;
  out.alarm = in.alarm;
  out.diverging = in.diverging;
}

template <typename From, typename To>
void copy_alarm(const From& in, To& out) {
  out.controller_id = in.controller_id;
  out.utime = in.utime;
  out.sample_sequence = in.sample_sequence;
  out.output = in.output;
  out.input = in.input;
  out.output_index = in.output_index;
  out.input_index = in.input_index;
  out.raised = in.raised;
  out.f = in.f;
  out.p_value = in.p_value;
  out.gamma = in.gamma;
  out.physics = in.physics;
  out.text = in.text;
}

// Everything of a status but its two arrays.
template <typename From, typename To>
void copy_status_scalars(const From& in, To& out) {
  out.controller_id = in.controller_id;
  out.utime = in.utime;
  out.uptime_ms = in.uptime_ms;
  out.ready = in.ready;
  out.effective_samples = in.effective_samples;
  out.raise_threshold = in.raise_threshold;
  out.clear_threshold = in.clear_threshold;
  out.samples_seen = in.samples_seen;
  out.samples_used = in.samples_used;
  out.dropped = in.dropped;
  out.gaps = in.gaps;
  out.missing = in.missing;
  out.duplicates = in.duplicates;
  out.out_of_order = in.out_of_order;
  out.restarts = in.restarts;
  out.malformed = in.malformed;
  out.nan_samples = in.nan_samples;
  out.alarms_raised = in.alarms_raised;
}

}  // namespace

void to_wire(const msg::Sample& in, mpm_lcm::sample_t& out) {
  out.controller_id = in.controller_id;
  out.session_id = in.session_id;
  out.seq = in.seq;
  out.utime = in.utime;
  out.u = in.u;
  out.n_u = length(in.u);
  out.y = in.y;
  out.n_y = length(in.y);
  out.sim_y = in.sim_y;
  out.n_sim_y = length(in.sim_y);
  // The two extra arrays share one length on the wire: send the common part.
  const std::size_t n_extra = std::min(in.extra_names.size(), in.extra_values.size());
  out.extra_names.assign(in.extra_names.begin(), in.extra_names.begin() + static_cast<std::ptrdiff_t>(n_extra));
  out.extra_values.assign(in.extra_values.begin(), in.extra_values.begin() + static_cast<std::ptrdiff_t>(n_extra));
  out.n_extra = static_cast<std::int32_t>(n_extra);
}

void to_wire(const msg::Alarm& in, mpm_lcm::alarm_t& out) { copy_alarm(in, out); }

void to_wire(const msg::Status& in, mpm_lcm::status_t& out) {
  copy_status_scalars(in, out);
  out.channels.resize(in.channels.size());
  for (std::size_t i = 0; i < in.channels.size(); ++i) copy_channel(in.channels[i], out.channels[i]);
  out.n_channels = length(in.channels);
  out.loops.resize(in.loops.size());
  for (std::size_t i = 0; i < in.loops.size(); ++i) copy_loop(in.loops[i], out.loops[i]);
  out.n_loops = length(in.loops);
}

bool from_wire(const mpm_lcm::sample_t& in, msg::Sample& out) {
  if (!has_length(in.u, in.n_u) || !has_length(in.y, in.n_y) || !has_length(in.sim_y, in.n_sim_y) ||
      !has_length(in.extra_names, in.n_extra) || !has_length(in.extra_values, in.n_extra)) {
    return false;
  }
  out.controller_id = in.controller_id;
  out.session_id = in.session_id;
  out.seq = in.seq;
  out.utime = in.utime;
  out.u.assign(in.u.begin(), in.u.end());
  out.y.assign(in.y.begin(), in.y.end());
  out.sim_y.assign(in.sim_y.begin(), in.sim_y.end());
  out.extra_names.resize(in.extra_names.size());
  for (std::size_t i = 0; i < in.extra_names.size(); ++i) out.extra_names[i] = in.extra_names[i];
  out.extra_values.assign(in.extra_values.begin(), in.extra_values.end());
  return true;
}

bool from_wire(const mpm_lcm::alarm_t& in, msg::Alarm& out) {
  copy_alarm(in, out);
  return true;
}

bool from_wire(const mpm_lcm::status_t& in, msg::Status& out) {
  if (!has_length(in.channels, in.n_channels) || !has_length(in.loops, in.n_loops)) return false;
  copy_status_scalars(in, out);
  out.channels.resize(in.channels.size());
  for (std::size_t i = 0; i < in.channels.size(); ++i) copy_channel(in.channels[i], out.channels[i]);
  out.loops.resize(in.loops.size());
  for (std::size_t i = 0; i < in.loops.size(); ++i) copy_loop(in.loops[i], out.loops[i]);
  return true;
}

}  // namespace mpm::transport::lcm_codec

namespace mpm::transport::lcm_codec {
namespace {

template <typename From, typename To>
void copy_diagnosis_scalars(const From& in, To& out) {
  out.controller_id = in.controller_id;
  out.utime = in.utime;
  out.sample_sequence = in.sample_sequence;
  out.output = in.output;
  out.input = in.input;
  out.output_index = in.output_index;
  out.input_index = in.input_index;
  out.window = in.window;
  out.found = in.found;
  out.physics = in.physics;
  out.channels = in.channels;
  out.holdout_improvement = in.holdout_improvement;
  out.text = in.text;
}

}  // namespace

void to_wire(const msg::Diagnosis& in, mpm_lcm::diagnosis_t& out) {
  copy_diagnosis_scalars(in, out);
  const std::size_t n = std::min(in.parameter_names.size(), in.parameter_values.size());
  out.parameter_names.assign(in.parameter_names.begin(), in.parameter_names.begin() + static_cast<std::ptrdiff_t>(n));
  out.parameter_values.assign(in.parameter_values.begin(), in.parameter_values.begin() + static_cast<std::ptrdiff_t>(n));
  out.n_parameters = static_cast<std::int32_t>(n);
}

bool from_wire(const mpm_lcm::diagnosis_t& in, msg::Diagnosis& out) {
  if (in.n_parameters < 0 || in.parameter_names.size() != static_cast<std::size_t>(in.n_parameters) ||
      in.parameter_values.size() != static_cast<std::size_t>(in.n_parameters)) {
    return false;
  }
  copy_diagnosis_scalars(in, out);
  out.parameter_names.assign(in.parameter_names.begin(), in.parameter_names.end());
  out.parameter_values.assign(in.parameter_values.begin(), in.parameter_values.end());
  return true;
}

}  // namespace mpm::transport::lcm_codec
