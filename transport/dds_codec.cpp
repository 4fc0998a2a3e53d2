#include "transport/dds_codec.hpp"

#include <algorithm>
#include <cstring>
#include <type_traits>

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

namespace {

// The scratch vector that holds the views of a nested message type.
std::vector<mpm_dds_ChannelStatus>& scratch_for(Scratch& s, const msg::ChannelStatus*) { return s.channels; }
std::vector<mpm_dds_LoopStatus>& scratch_for(Scratch& s, const msg::LoopStatus*) { return s.loops; }

// A view of every field of `in` in `out` (the idlc type: the members have
// the same names but for the NamedValues sequences). Nested messages and
// named values are viewed through `scratch`.
template <class M, class Dds>
void view_fields(const M& in, Dds& out, Scratch& scratch) {
  msg::for_each_field<M>([&](const auto& field) {
    using Field = std::remove_cvref_t<decltype(field)>;
    if constexpr (msg::is<Field>(msg::FieldKind::kArray)) {
      using Element = msg::ElementOf<M, Field>;
      const auto& items = field.get(in);
      if constexpr (std::is_arithmetic_v<Element>) {
        field.get(out) = view(items);
      } else {
        auto& views = scratch_for(scratch, static_cast<const Element*>(nullptr));
        views.resize(items.size());
        for (std::size_t i = 0; i < items.size(); ++i) {
          views[i] = {};
          view_fields(items[i], views[i], scratch);
        }
        field.get(out) = view_of<std::remove_cvref_t<decltype(field.get(out))>>(views);
      }
    } else if constexpr (msg::is<Field>(msg::FieldKind::kNamedValues)) {
      const auto& names = field.names(in);
      const auto& values = field.values(in);
      const std::size_t n = std::min(names.size(), values.size());
      scratch.extra.resize(n);
      for (std::size_t i = 0; i < n; ++i) scratch.extra[i] = {view(names[i]), values[i]};
      field.dds(out) = view_of<dds_sequence_mpm_dds_NamedValue>(scratch.extra);
    } else if constexpr (std::is_same_v<std::remove_cvref_t<decltype(field.get(in))>, std::string>) {
      field.get(out) = view(field.get(in));
    } else {
      field.get(out) = field.get(in);
    }
  });
}

// Copies every field of `in` (the idlc type) into `out`, assigning into the
// storage it has.
template <class M, class Dds>
void copy_fields(const Dds& in, M& out) {
  msg::for_each_field<M>([&](const auto& field) {
    using Field = std::remove_cvref_t<decltype(field)>;
    if constexpr (msg::is<Field>(msg::FieldKind::kArray)) {
      using Element = msg::ElementOf<M, Field>;
      const auto& seq = field.get(in);
      auto& items = field.get(out);
      if constexpr (std::is_arithmetic_v<Element>) {
        assign(items, seq);
      } else {
        items.resize(seq._length);
        for (std::uint32_t i = 0; i < seq._length; ++i) copy_fields(seq._buffer[i], items[i]);
      }
    } else if constexpr (msg::is<Field>(msg::FieldKind::kNamedValues)) {
      const auto& seq = field.dds(in);
      auto& names = field.names(out);
      auto& values = field.values(out);
      names.resize(seq._length);
      values.resize(seq._length);
      for (std::uint32_t i = 0; i < seq._length; ++i) {
        assign(names[i], seq._buffer[i].name);
        values[i] = seq._buffer[i].value;
      }
    } else if constexpr (std::is_same_v<std::remove_cvref_t<decltype(field.get(out))>, std::string>) {
      assign(field.get(out), field.get(in));
    } else {
      field.get(out) = field.get(in);
    }
  });
}

}  // namespace

void to_wire(const msg::Sample& in, mpm_dds_Sample& out, Scratch& scratch) { view_fields(in, out, scratch); }
void to_wire(const msg::Alarm& in, mpm_dds_Alarm& out) {
  Scratch none;  // an alarm has no sequences
  view_fields(in, out, none);
}
void to_wire(const msg::Status& in, mpm_dds_Status& out, Scratch& scratch) { view_fields(in, out, scratch); }
void to_wire(const msg::Diagnosis& in, mpm_dds_Diagnosis& out, Scratch& scratch) {
  view_fields(in, out, scratch);
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

void from_wire(const mpm_dds_Sample& in, msg::Sample& out) { copy_fields(in, out); }
void from_wire(const mpm_dds_Alarm& in, msg::Alarm& out) { copy_fields(in, out); }
void from_wire(const mpm_dds_Status& in, msg::Status& out) { copy_fields(in, out); }
void from_wire(const mpm_dds_Diagnosis& in, msg::Diagnosis& out) { copy_fields(in, out); }

}  // namespace mpm::transport::dds_codec
