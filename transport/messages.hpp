// The messages of the monitor as plain C++ data, independent of the
// transport that carries them (messages/mpm.lcm and messages/mpm.idl hold the
// wire definitions; README.md documents the fields).
//
// Each message's fields are listed once, by for_each_field<M>() at the end of
// this file: the LCM codec and checked decoder, the DDS codec and the JSON
// lines are all driven by that list, and tests/transport/test_message_fields
// checks mpm.lcm and mpm.idl against it (names, types, order). A new field is
// a member here, a row in its list and a line in each of the two files.
//
// The daemon reuses one Sample object per queue slot: assigning into vectors
// that already have the capacity does not allocate, so the receive path is
// allocation free once the first samples have sized them.
#pragma once

#include <cstdint>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace mpm::msg {

struct Sample {
  std::string controller_id;
  std::int64_t session_id = 0;  // random per publisher start; 0 = not used
  std::int64_t seq = 0;         // 1, 2, 3, ... per session
  std::int64_t utime = 0;       // microseconds since the Unix epoch
  std::vector<double> u;        // plant inputs, plant file order
  std::vector<double> y;        // plant outputs, plant file order
  std::vector<double> sim_y;    // empty, or the controller's model prediction of y
  std::vector<std::string> extra_names;
  std::vector<double> extra_values;
};

struct Alarm {
  std::string controller_id;
  std::int64_t utime = 0;
  std::int64_t sample_sequence = 0;
  std::string output;
  std::string input;
  std::int32_t output_index = 0;
  std::int32_t input_index = 0;
  bool raised = false;
  double f = 0.0;
  double p_value = 1.0;
  double gamma = 0.0;     // NaN when unknown
  std::string physics;    // "" when unknown
  std::string text;
};

// The offline diagnosis of a raised output (transport/README.md).
struct Diagnosis {
  std::string controller_id;
  std::int64_t utime = 0;
  std::int64_t sample_sequence = 0;
  std::string output;
  std::string input;
  std::int32_t output_index = 0;
  std::int32_t input_index = 0;
  std::int32_t window = 0;
  bool found = false;
  std::string physics;   // "" when nothing was found
  std::string channels;
  std::vector<std::string> parameter_names;
  std::vector<double> parameter_values;
  double holdout_improvement = 0.0;
  std::string text;
};

struct ChannelStatus {
  std::string output;
  std::string input;
  double f_pairwise = 0.0;
  double f_conditional = 0.0;
  double lr = 0.0;
  double p_value = 1.0;
  double gamma = 0.0;
  bool alarm = false;
};

struct LoopStatus {
  std::string output;
  double residual_variance = 0.0;
  double sigma1 = 0.0;
  double sigma_full = 0.0;
  bool alarm = false;
  bool diverging = false;
};

struct Status {
  std::string controller_id;
  std::int64_t utime = 0;
  std::int64_t uptime_ms = 0;
  bool ready = false;
  double effective_samples = 0.0;
  double raise_threshold = 0.0;
  double clear_threshold = 0.0;
  std::int64_t samples_seen = 0;
  std::int64_t samples_used = 0;
  std::int64_t dropped = 0;
  std::int64_t gaps = 0;
  std::int64_t missing = 0;
  std::int64_t duplicates = 0;
  std::int64_t out_of_order = 0;
  std::int64_t restarts = 0;
  std::int64_t malformed = 0;
  std::int64_t nan_samples = 0;
  std::int64_t alarms_raised = 0;
  std::vector<ChannelStatus> channels;
  std::vector<LoopStatus> loops;
};

// --- The field lists ---------------------------------------------------------
//
// for_each_field<M>(f) calls f once per field of M, in wire order, with one
// of three descriptors (Scalar, Array, NamedValues; tell them apart by
// their static `kind`). Each carries the field's names and accessors: generic
// lambdas `get(m)` that return the member of that name of ANY struct that has
// it, so one list serves our structs, lcm-gen's and idlc's alike (accessors
// of members only one side has, such as LCM's n_u, are only called there).

// The names of a field.
struct Names {
  const char* name;              // in messages.hpp, mpm.lcm and mpm.idl
  const char* json = nullptr;    // its key in the JSON lines when not `name`
  bool key = false;              // a DDS @key (keys come first in mpm.idl)
  bool line = false;             // a string for people: 4 x the wire's string cap
  const char* json_true = nullptr;   // a bool written as one of two words
  const char* json_false = nullptr;
  const char* json_key() const noexcept { return json != nullptr ? json : name; }
};

enum class FieldKind : std::uint8_t { kScalar, kArray, kNamedValues };

// A number, a bool or a string.
template <class Get>
struct Scalar {
  static constexpr FieldKind kind = FieldKind::kScalar;
  Names names;
  Get get;
};

// A variable array of doubles or of a nested message; on LCM its int32
// length field `lcm_length_name` comes first.
template <class Get, class Length>
struct Array {
  static constexpr FieldKind kind = FieldKind::kArray;
  Names names;
  const char* lcm_length_name;
  Get get;
  Length lcm_length;
};

// Two arrays of one length, names and values: on LCM two arrays after one
// int32 length, in DDS one sequence<NamedValue> `dds_name`, in JSON one
// object {name: value} under `json`.
template <class GetNames, class GetValues, class Length, class Dds>
struct NamedValues {
  static constexpr FieldKind kind = FieldKind::kNamedValues;
  const char* names_name;
  const char* values_name;
  const char* lcm_length_name;
  const char* dds_name;
  const char* json;
  GetNames names;
  GetValues values;
  Length lcm_length;
  Dds dds;
};

// Deduction guides: aggregate class template argument deduction (C++20,
// P1816) is in GCC 11 but not in Clang 14, which builds the fuzz targets.
template <class Get>
Scalar(Names, Get) -> Scalar<Get>;
template <class Get, class Length>
Array(Names, const char*, Get, Length) -> Array<Get, Length>;
template <class GetNames, class GetValues, class Length, class Dds>
NamedValues(const char*, const char*, const char*, const char*, const char*, GetNames, GetValues, Length, Dds)
    -> NamedValues<GetNames, GetValues, Length, Dds>;

// What a message is called on each wire; specialised below.
template <class M>
struct Fields;

template <class M, class F>
constexpr void for_each_field(F&& f) {
  Fields<M>::visit(f);
}

#define MPM_GET(member) [](auto& m) -> auto& { return m.member; }
#define MPM_SCALAR(member, ...) f(Scalar{Names{.name = #member, __VA_ARGS__}, MPM_GET(member)})
#define MPM_ARRAY(member, ...) \
  f(Array{Names{.name = #member, __VA_ARGS__}, "n_" #member, MPM_GET(member), MPM_GET(n_##member)})
#define MPM_NAMED_VALUES(names_, values_, length_, dds_)                                                   \
  f(NamedValues{#names_, #values_, #length_, #dds_, #dds_, MPM_GET(names_), MPM_GET(values_), MPM_GET(length_), \
                MPM_GET(dds_)})

template <>
struct Fields<Sample> {
  static constexpr const char* lcm = "sample_t";
  static constexpr const char* idl = "Sample";
  static constexpr const char* json_type = "sample";
  template <class F>
  static constexpr void visit(F& f) {
    MPM_SCALAR(controller_id, .json = "controller", .key = true);
    MPM_SCALAR(session_id);
    MPM_SCALAR(seq);
    MPM_SCALAR(utime);
    MPM_ARRAY(u);
    MPM_ARRAY(y);
    MPM_ARRAY(sim_y);
    MPM_NAMED_VALUES(extra_names, extra_values, n_extra, extra);
  }
};

// The first fields of an alarm and of a diagnosis: the channel and the
// sample an event concerns (DDS keys: controller, output, input).
template <class F>
constexpr void channel_event_fields(F& f) {
    MPM_SCALAR(controller_id, .json = "controller", .key = true);
    MPM_SCALAR(utime);
    MPM_SCALAR(sample_sequence);
    MPM_SCALAR(output, .key = true);
    MPM_SCALAR(input, .key = true);
    MPM_SCALAR(output_index);
    MPM_SCALAR(input_index);
}

template <>
struct Fields<Alarm> {
  static constexpr const char* lcm = "alarm_t";
  static constexpr const char* idl = "Alarm";
  static constexpr const char* json_type = "alarm";
  template <class F>
  static constexpr void visit(F& f) {
    channel_event_fields(f);
    MPM_SCALAR(raised, .json = "state", .json_true = "raised", .json_false = "cleared");
    MPM_SCALAR(f, .json = "F");
    MPM_SCALAR(p_value);
    MPM_SCALAR(gamma);
    MPM_SCALAR(physics);
    MPM_SCALAR(text, .line = true);
  }
};

template <>
struct Fields<Diagnosis> {
  static constexpr const char* lcm = "diagnosis_t";
  static constexpr const char* idl = "Diagnosis";
  static constexpr const char* json_type = "diagnosis";
  template <class F>
  static constexpr void visit(F& f) {
    channel_event_fields(f);
    MPM_SCALAR(window);
    MPM_SCALAR(found);
    MPM_SCALAR(physics);
    MPM_SCALAR(channels, .line = true);
    MPM_NAMED_VALUES(parameter_names, parameter_values, n_parameters, parameters);
    MPM_SCALAR(holdout_improvement);
    MPM_SCALAR(text, .line = true);
  }
};

template <>
struct Fields<ChannelStatus> {
  static constexpr const char* lcm = "channel_status_t";
  static constexpr const char* idl = "ChannelStatus";
  static constexpr const char* json_type = nullptr;  // nested: no "type"
  template <class F>
  static constexpr void visit(F& f) {
    MPM_SCALAR(output);
    MPM_SCALAR(input);
    MPM_SCALAR(f_pairwise, .json = "F");
    MPM_SCALAR(f_conditional, .json = "F_conditional");
    MPM_SCALAR(lr, .json = "LR");
    MPM_SCALAR(p_value);
    MPM_SCALAR(gamma);
    MPM_SCALAR(alarm);
  }
};

template <>
struct Fields<LoopStatus> {
  static constexpr const char* lcm = "loop_status_t";
  static constexpr const char* idl = "LoopStatus";
  static constexpr const char* json_type = nullptr;
  template <class F>
  static constexpr void visit(F& f) {
    MPM_SCALAR(output);
    MPM_SCALAR(residual_variance);
    MPM_SCALAR(sigma1);
    MPM_SCALAR(sigma_full);
    MPM_SCALAR(alarm);
    MPM_SCALAR(diverging);
  }
};

template <>
struct Fields<Status> {
  static constexpr const char* lcm = "status_t";
  static constexpr const char* idl = "Status";
  static constexpr const char* json_type = "status";
  template <class F>
  static constexpr void visit(F& f) {
    MPM_SCALAR(controller_id, .json = "controller", .key = true);
    MPM_SCALAR(utime);
    MPM_SCALAR(uptime_ms);
    MPM_SCALAR(ready);
    MPM_SCALAR(effective_samples);
    MPM_SCALAR(raise_threshold);
    MPM_SCALAR(clear_threshold);
    MPM_SCALAR(samples_seen);
    MPM_SCALAR(samples_used);
    MPM_SCALAR(dropped);
    MPM_SCALAR(gaps);
    MPM_SCALAR(missing);
    MPM_SCALAR(duplicates);
    MPM_SCALAR(out_of_order);
    MPM_SCALAR(restarts);
    MPM_SCALAR(malformed);
    MPM_SCALAR(nan_samples);
    MPM_SCALAR(alarms_raised);
    MPM_ARRAY(channels);
    MPM_ARRAY(loops);
  }
};

#undef MPM_NAMED_VALUES
#undef MPM_ARRAY
#undef MPM_SCALAR
#undef MPM_GET

// The element type of an Array field of M: double, or a nested message.
template <class Field>
constexpr bool is(FieldKind kind) {
  return std::remove_cvref_t<Field>::kind == kind;
}

template <class M, class Field>
using ElementOf = typename std::remove_cvref_t<decltype(std::declval<Field>().get(std::declval<M&>()))>::value_type;

}  // namespace mpm::msg
