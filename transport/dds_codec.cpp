#include "transport/dds_codec.hpp"

#include <algorithm>
#include <cstring>

namespace mpm::transport::dds_codec {

namespace {

// Cyclone's C types take char* and non-const buffers; it only reads them when
// writing, so viewing our const data through them is safe.
char* view(const std::string& s) { return const_cast<char*>(s.c_str()); }

dds_sequence_double view(const std::vector<double>& v) {
  dds_sequence_double seq{};
  seq._length = seq._maximum = static_cast<std::uint32_t>(v.size());
  seq._buffer = const_cast<double*>(v.data());
  seq._release = false;
  return seq;
}

template <typename Seq, typename T>
Seq view_of(std::vector<T>& v) {
  Seq seq{};
  seq._length = seq._maximum = static_cast<std::uint32_t>(v.size());
  seq._buffer = v.data();
  seq._release = false;
  return seq;
}

void assign(std::vector<double>& out, const dds_sequence_double& in) {
  out.assign(in._buffer, in._buffer + in._length);
}

void assign(std::string& out, const char* in) {
  if (in == nullptr) {
    out.clear();
  } else {
    out.assign(in);
  }
}

}  // namespace

void to_wire(const msg::Sample& in, mpm_dds_Sample& out, Scratch& scratch) {
  out.controller_id = view(in.controller_id);
  out.session_id = in.session_id;
  out.seq = in.seq;
  out.utime = in.utime;
  out.u = view(in.u);
  out.y = view(in.y);
  out.sim_y = view(in.sim_y);
  const std::size_t n = std::min(in.extra_names.size(), in.extra_values.size());
  scratch.extra.resize(n);
  for (std::size_t i = 0; i < n; ++i) scratch.extra[i] = {view(in.extra_names[i]), in.extra_values[i]};
  out.extra = view_of<dds_sequence_mpm_dds_NamedValue>(scratch.extra);
}

void to_wire(const msg::Alarm& in, mpm_dds_Alarm& out) {
  out.controller_id = view(in.controller_id);
  out.output = view(in.output);
  out.input = view(in.input);
  out.utime = in.utime;
  out.sample_sequence = in.sample_sequence;
  out.output_index = in.output_index;
  out.input_index = in.input_index;
  out.raised = in.raised;
  out.f = in.f;
  out.p_value = in.p_value;
  out.gamma = in.gamma;
  out.physics = view(in.physics);
  out.text = view(in.text);
}

namespace {

// The numeric fields of a status have the same names on both sides: one copy
// serves both directions (strings and sequences are converted by hand).
template <typename From, typename To>
void copy_status_numbers(const From& in, To& out) {
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

void to_wire(const msg::Status& in, mpm_dds_Status& out, Scratch& scratch) {
  out.controller_id = view(in.controller_id);
  copy_status_numbers(in, out);
  scratch.channels.resize(in.channels.size());
  for (std::size_t i = 0; i < in.channels.size(); ++i) {
    const auto& c = in.channels[i];
    scratch.channels[i] = {view(c.output), view(c.input), c.f_pairwise, c.f_conditional,
                           c.lr,           c.p_value,     c.gamma,      c.alarm};
  }
  out.channels = view_of<dds_sequence_mpm_dds_ChannelStatus>(scratch.channels);
  scratch.loops.resize(in.loops.size());
  for (std::size_t i = 0; i < in.loops.size(); ++i) {
    const auto& l = in.loops[i];
    scratch.loops[i] = {view(l.output), l.residual_variance, l.sigma1, l.sigma_full, l.alarm, l.diverging};
  }
  out.loops = view_of<dds_sequence_mpm_dds_LoopStatus>(scratch.loops);
}

namespace {

// A string of at most `max` bytes (strnlen never reads past max + 1 bytes).
bool string_ok(const char* s, std::uint32_t max) noexcept {
  return s == nullptr || ::strnlen(s, std::size_t{max} + 1) <= max;
}

bool dimension_ok(std::uint32_t n, std::uint32_t expected, std::uint32_t cap) noexcept {
  return expected != 0 ? n == expected : n <= cap;
}

}  // namespace

WireError check(const mpm_dds_Sample& in, const SampleLimits& limits) noexcept {
  if (!string_ok(in.controller_id, limits.max_string)) return WireError::kStringTooLong;
  if (!dimension_ok(in.u._length, limits.n_u, limits.max_channels)) return WireError::kWrongInputs;
  if (!dimension_ok(in.y._length, limits.n_y, limits.max_channels)) return WireError::kWrongOutputs;
  if (in.sim_y._length != 0 && in.sim_y._length != in.y._length) return WireError::kWrongSimOutputs;
  if (in.extra._length > limits.max_extra) return WireError::kTooManyExtras;
  for (std::uint32_t i = 0; i < in.extra._length; ++i) {
    if (!string_ok(in.extra._buffer[i].name, limits.max_string)) return WireError::kStringTooLong;
  }
  // A length with no buffer would be a broken deserialiser; refuse, not crash.
  if ((in.u._length && !in.u._buffer) || (in.y._length && !in.y._buffer) ||
      (in.sim_y._length && !in.sim_y._buffer) || (in.extra._length && !in.extra._buffer)) {
    return WireError::kBadLength;
  }
  return WireError::kNone;
}

WireError from_wire(const mpm_dds_Sample& in, const SampleLimits& limits, msg::Sample& out) {
  const WireError error = check(in, limits);
  if (error == WireError::kNone) from_wire(in, out);
  return error;
}

void from_wire(const mpm_dds_Sample& in, msg::Sample& out) {
  assign(out.controller_id, in.controller_id);
  out.session_id = in.session_id;
  out.seq = in.seq;
  out.utime = in.utime;
  assign(out.u, in.u);
  assign(out.y, in.y);
  assign(out.sim_y, in.sim_y);
  out.extra_names.resize(in.extra._length);
  out.extra_values.resize(in.extra._length);
  for (std::uint32_t i = 0; i < in.extra._length; ++i) {
    assign(out.extra_names[i], in.extra._buffer[i].name);
    out.extra_values[i] = in.extra._buffer[i].value;
  }
}

void from_wire(const mpm_dds_Alarm& in, msg::Alarm& out) {
  assign(out.controller_id, in.controller_id);
  assign(out.output, in.output);
  assign(out.input, in.input);
  out.utime = in.utime;
  out.sample_sequence = in.sample_sequence;
  out.output_index = in.output_index;
  out.input_index = in.input_index;
  out.raised = in.raised;
  out.f = in.f;
  out.p_value = in.p_value;
  out.gamma = in.gamma;
  assign(out.physics, in.physics);
  assign(out.text, in.text);
}

void from_wire(const mpm_dds_Status& in, msg::Status& out) {
  assign(out.controller_id, in.controller_id);
  copy_status_numbers(in, out);
  out.channels.resize(in.channels._length);
  for (std::uint32_t i = 0; i < in.channels._length; ++i) {
    const auto& c = in.channels._buffer[i];
    auto& o = out.channels[i];
    assign(o.output, c.output);
    assign(o.input, c.input);
    o.f_pairwise = c.f_pairwise;
    o.f_conditional = c.f_conditional;
    o.lr = c.lr;
    o.p_value = c.p_value;
    o.gamma = c.gamma;
    o.alarm = c.alarm;
  }
  out.loops.resize(in.loops._length);
  for (std::uint32_t i = 0; i < in.loops._length; ++i) {
    const auto& l = in.loops._buffer[i];
    auto& o = out.loops[i];
    assign(o.output, l.output);
    o.residual_variance = l.residual_variance;
    o.sigma1 = l.sigma1;
    o.sigma_full = l.sigma_full;
    o.alarm = l.alarm;
    o.diverging = l.diverging;
  }
}

}  // namespace mpm::transport::dds_codec

namespace mpm::transport::dds_codec {

void to_wire(const msg::Diagnosis& in, mpm_dds_Diagnosis& out, Scratch& scratch) {
  out.controller_id = view(in.controller_id);
  out.output = view(in.output);
  out.input = view(in.input);
  out.utime = in.utime;
  out.sample_sequence = in.sample_sequence;
  out.output_index = in.output_index;
  out.input_index = in.input_index;
  out.window = in.window;
  out.found = in.found;
  out.physics = view(in.physics);
  out.channels = view(in.channels);
  const std::size_t n = std::min(in.parameter_names.size(), in.parameter_values.size());
  scratch.extra.resize(n);
  for (std::size_t i = 0; i < n; ++i) scratch.extra[i] = {view(in.parameter_names[i]), in.parameter_values[i]};
  out.parameters = view_of<dds_sequence_mpm_dds_NamedValue>(scratch.extra);
  out.holdout_improvement = in.holdout_improvement;
  out.text = view(in.text);
}

void from_wire(const mpm_dds_Diagnosis& in, msg::Diagnosis& out) {
  assign(out.controller_id, in.controller_id);
  assign(out.output, in.output);
  assign(out.input, in.input);
  out.utime = in.utime;
  out.sample_sequence = in.sample_sequence;
  out.output_index = in.output_index;
  out.input_index = in.input_index;
  out.window = in.window;
  out.found = in.found;
  assign(out.physics, in.physics);
  assign(out.channels, in.channels);
  out.parameter_names.resize(in.parameters._length);
  out.parameter_values.resize(in.parameters._length);
  for (std::uint32_t i = 0; i < in.parameters._length; ++i) {
    assign(out.parameter_names[i], in.parameters._buffer[i].name);
    out.parameter_values[i] = in.parameters._buffer[i].value;
  }
  out.holdout_improvement = in.holdout_improvement;
  assign(out.text, in.text);
}

}  // namespace mpm::transport::dds_codec
