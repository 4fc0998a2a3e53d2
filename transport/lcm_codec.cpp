#include "transport/lcm_codec.hpp"

#include <algorithm>
#include <type_traits>

namespace mpm::transport::lcm_codec {

namespace {

template <typename T>
bool has_length(const std::vector<T>& v, std::int32_t n) {
  return n >= 0 && v.size() == static_cast<std::size_t>(n);
}

// Every array length of the wire message `in` (of plain type M) agrees with
// its array, nested messages included.
template <class M, class Wire>
bool lengths_ok(const Wire& in) {
  bool ok = true;
  msg::for_each_field<M>([&](const auto& field) {
    using Field = std::remove_cvref_t<decltype(field)>;
    if constexpr (msg::is<Field>(msg::FieldKind::kArray)) {
      const auto& items = field.get(in);
      ok = ok && has_length(items, field.lcm_length(in));
      if constexpr (!std::is_arithmetic_v<msg::ElementOf<M, Field>>) {
        for (const auto& item : items) ok = ok && lengths_ok<msg::ElementOf<M, Field>>(item);
      }
    } else if constexpr (msg::is<Field>(msg::FieldKind::kNamedValues)) {
      ok = ok && has_length(field.names(in), field.lcm_length(in)) && has_length(field.values(in), field.lcm_length(in));
    }
  });
  return ok;
}

// Copies every field of `in` into `out` (one of them our M, the other the
// lcm-gen type: the members have the same names) and, towards the wire,
// sets the array lengths. Vectors are assigned into the storage they have.
template <class M, bool kToWire, class From, class To>
void copy(const From& in, To& out) {
  msg::for_each_field<M>([&](const auto& field) {
    using Field = std::remove_cvref_t<decltype(field)>;
    if constexpr (msg::is<Field>(msg::FieldKind::kArray)) {
      const auto& from = field.get(in);
      auto& to = field.get(out);
      using Element = msg::ElementOf<M, Field>;
      if constexpr (std::is_arithmetic_v<Element>) {
        to.assign(from.begin(), from.end());
      } else {
        to.resize(from.size());
        for (std::size_t i = 0; i < from.size(); ++i) copy<Element, kToWire>(from[i], to[i]);
      }
      if constexpr (kToWire) field.lcm_length(out) = static_cast<std::int32_t>(from.size());
    } else if constexpr (msg::is<Field>(msg::FieldKind::kNamedValues)) {
      // The two arrays share one length on the wire: the common part goes.
      const auto& names = field.names(in);
      const auto& values = field.values(in);
      const auto n = static_cast<std::ptrdiff_t>(std::min(names.size(), values.size()));
      field.names(out).assign(names.begin(), names.begin() + n);
      field.values(out).assign(values.begin(), values.begin() + n);
      if constexpr (kToWire) field.lcm_length(out) = static_cast<std::int32_t>(n);
    } else {
      field.get(out) = field.get(in);
    }
  });
}

template <class M, class Wire>
void to_wire_impl(const M& in, Wire& out) {
  copy<M, true>(in, out);
}

template <class M, class Wire>
bool from_wire_impl(const Wire& in, M& out) {
  if (!lengths_ok<M>(in)) return false;
  copy<M, false>(in, out);
  return true;
}

}  // namespace

void to_wire(const msg::Sample& in, mpm_lcm::sample_t& out) { to_wire_impl(in, out); }
void to_wire(const msg::Alarm& in, mpm_lcm::alarm_t& out) { to_wire_impl(in, out); }
void to_wire(const msg::Status& in, mpm_lcm::status_t& out) { to_wire_impl(in, out); }
void to_wire(const msg::Diagnosis& in, mpm_lcm::diagnosis_t& out) { to_wire_impl(in, out); }

bool from_wire(const mpm_lcm::sample_t& in, msg::Sample& out) { return from_wire_impl(in, out); }
bool from_wire(const mpm_lcm::alarm_t& in, msg::Alarm& out) { return from_wire_impl(in, out); }
bool from_wire(const mpm_lcm::status_t& in, msg::Status& out) { return from_wire_impl(in, out); }
bool from_wire(const mpm_lcm::diagnosis_t& in, msg::Diagnosis& out) { return from_wire_impl(in, out); }

}  // namespace mpm::transport::lcm_codec
