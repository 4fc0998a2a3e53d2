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

void to_wire(const msg::ChannelStatus& in, mpm_lcm::channel_status_t& out) {
  out.output = in.output;
  out.input = in.input;
  out.f_pairwise = in.f_pairwise;
  out.f_conditional = in.f_conditional;
  out.lr = in.lr;
  out.p_value = in.p_value;
  out.gamma = in.gamma;
  out.alarm = in.alarm;
}

void to_wire(const msg::LoopStatus& in, mpm_lcm::loop_status_t& out) {
  out.output = in.output;
  out.residual_variance = in.residual_variance;
  out.sigma1 = in.sigma1;
  out.sigma_full = in.sigma_full;
  out.alarm = in.alarm;
  out.diverging = in.diverging;
}

void from_wire(const mpm_lcm::channel_status_t& in, msg::ChannelStatus& out) {
  out.output = in.output;
  out.input = in.input;
  out.f_pairwise = in.f_pairwise;
  out.f_conditional = in.f_conditional;
  out.lr = in.lr;
  out.p_value = in.p_value;
  out.gamma = in.gamma;
  out.alarm = in.alarm;
}

void from_wire(const mpm_lcm::loop_status_t& in, msg::LoopStatus& out) {
  out.output = in.output;
  out.residual_variance = in.residual_variance;
  out.sigma1 = in.sigma1;
  out.sigma_full = in.sigma_full;
  out.alarm = in.alarm;
  out.diverging = in.diverging;
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

void to_wire(const msg::Alarm& in, mpm_lcm::alarm_t& out) {
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

void to_wire(const msg::Status& in, mpm_lcm::status_t& out) {
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
  out.channels.resize(in.channels.size());
  for (std::size_t i = 0; i < in.channels.size(); ++i) to_wire(in.channels[i], out.channels[i]);
  out.n_channels = length(in.channels);
  out.loops.resize(in.loops.size());
  for (std::size_t i = 0; i < in.loops.size(); ++i) to_wire(in.loops[i], out.loops[i]);
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
  return true;
}

bool from_wire(const mpm_lcm::status_t& in, msg::Status& out) {
  if (!has_length(in.channels, in.n_channels) || !has_length(in.loops, in.n_loops)) return false;
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
  out.channels.resize(in.channels.size());
  for (std::size_t i = 0; i < in.channels.size(); ++i) from_wire(in.channels[i], out.channels[i]);
  out.loops.resize(in.loops.size());
  for (std::size_t i = 0; i < in.loops.size(); ++i) from_wire(in.loops[i], out.loops[i]);
  return true;
}

}  // namespace mpm::transport::lcm_codec
