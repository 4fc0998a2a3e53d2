// expect_same_message(out, in): every field of a message that went through a
// codec or a transport equals the one sent, field by field from the message's
// own field list (messages.hpp for_each_field), so a field added there is
// checked by every round-trip test without touching them. A failure names
// the field (and the element of a nested array).
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <type_traits>

#include "transport/messages.hpp"

namespace mpm::test {

template <class T>
void expect_same_value(const T& out, const T& in, const std::string& where) {
  if constexpr (std::is_floating_point_v<T>) {
    // NaN means "not computed" in a status (gamma): it must arrive as NaN.
    EXPECT_TRUE((std::isnan(out) && std::isnan(in)) || out == in) << where << ": " << out << " != " << in;
  } else {
    EXPECT_EQ(out, in) << where;
  }
}

template <class M>
void expect_same_message(const M& out, const M& in, const std::string& where = "") {
  msg::for_each_field<M>([&](const auto& field) {
    using Field = decltype(field);
    if constexpr (msg::is<Field>(msg::FieldKind::kNamedValues)) {
      expect_same_value(field.names(out), field.names(in), where + field.names_name);
      expect_same_value(field.values(out), field.values(in), where + field.values_name);
    } else if constexpr (msg::is<Field>(msg::FieldKind::kArray)) {
      if constexpr (std::is_arithmetic_v<msg::ElementOf<const M, Field>>) {
        expect_same_value(field.get(out), field.get(in), where + field.names.name);
      } else {  // nested messages, element by element
        const auto& a = field.get(out);
        const auto& b = field.get(in);
        ASSERT_EQ(a.size(), b.size()) << where << field.names.name;
        for (std::size_t i = 0; i < a.size(); ++i)
          expect_same_message(a[i], b[i], where + field.names.name + "[" + std::to_string(i) + "].");
      }
    } else {
      expect_same_value(field.get(out), field.get(in), where + field.names.name);
    }
  });
}

}  // namespace mpm::test
