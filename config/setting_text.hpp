// A setting given as text (a YAML scalar, a command-line value) stored in its
// row (core/field_table.hpp): the word ("auto"), a bool's two words, a number
// in the row's range (checked before it is stored, so a whole number never
// overflows its type), a name, or numbers separated by commas. The YAML
// reader and `mpm monitor`'s flags both go through it, so a file and a flag
// accept the same values.
#pragma once

#include <cmath>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include "core/field_table.hpp"

namespace mpm::config {

// "" when stored, else what is wrong ("expected an integer, got 'ten'",
// "forgetting must be in (0.9, 1], got 1.5"); `s` is unchanged then.
template <class S>
std::string set_from_text(const FieldRow<S>& row, S& s, const std::string& text) {
  if (row.word && text == row.word) {
    row.on_word(s);
    return "";
  }
  const auto number = [](const std::string& t, double& v) {
    char* end = nullptr;
    v = std::strtod(t.c_str(), &end);
    return !t.empty() && *end == '\0' && std::isfinite(v);
  };
  return std::visit(
      [&](auto* p) -> std::string {
        using T = std::remove_pointer_t<decltype(p)>;
        if constexpr (std::is_same_v<T, bool>) {
          if (text != row.false_word && text != row.true_word)
            return std::string("expected ") + row.false_word + " or " + row.true_word + ", got \"" + text + "\"";
          *p = text == row.true_word;
        } else if constexpr (std::is_same_v<T, std::string>) {
          if (text.empty()) return "expected a name";
          *p = text;
        } else if constexpr (std::is_same_v<T, std::vector<double>>) {
          std::vector<double> list;
          std::stringstream items(text);
          for (std::string item; std::getline(items, item, ',');) {
            double v = 0;
            if (!number(item, v)) return "expected numbers separated by commas, got \"" + text + "\"";
            list.push_back(v);
          }
          *p = std::move(list);
        } else {
          double v = 0;
          if (!number(text, v))
            return std::string(std::is_same_v<T, double> ? "expected a number" : "expected an integer") + ", got \"" +
                   text + "\"";
          if constexpr (!std::is_same_v<T, double>) {  // a whole number that fits T
            // (max + 1.0 rounds to 2^63 and 2^64 for the 64-bit types: strictly below it fits)
            if (v != std::floor(v) || v < static_cast<double>(std::numeric_limits<T>::lowest()) ||
                !(v < static_cast<double>(std::numeric_limits<T>::max()) + 1.0))
              return "expected an integer, got \"" + text + "\"";
          }
          if (!row.range.contains(v))
            return std::string(row.key) + " must be " + row.range.describe(row.word) + ", got " + text;
          *p = static_cast<T>(v);
        }
        return "";
      },
      row.ref(s));
}

}  // namespace mpm::config
