#include "config/limits.hpp"

#include <cstdio>
#include <type_traits>
#include <variant>

namespace mpm::config {

const std::vector<FieldRow<Limits>>& Limits::fields() {
  // The upper ends keep every cap a number the loaders can still handle
  // (sizes that fit in memory, delays a diagnosis can scan).
  using L = Limits;
  static const std::vector<FieldRow<L>> rows = {
      {"max_inputs", [](L& l) { return &l.max_inputs; }, {.min = 1, .max = 10000, .whole = true}, "plant inputs"},
      {"max_outputs", [](L& l) { return &l.max_outputs; }, {.min = 1, .max = 10000, .whole = true}, "plant outputs"},
      {"max_poly_length", [](L& l) { return &l.max_poly_length; }, {.min = 1, .max = 100000, .whole = true},
       "coefficients in one num or den"},
      {"max_delay_samples", [](L& l) { return &l.max_delay_samples; }, {.min = 0, .max = 1e7, .whole = true},
       "pure delay of one channel, in samples"},
      {"max_states", [](L& l) { return &l.max_states; }, {.min = 1, .max = 10000, .whole = true},
       "states of a state_space plant"},
      {"max_yaml_bytes", [](L& l) { return &l.max_yaml_bytes; }, {.min = 1, .max = 0x1p40, .whole = true},
       "bytes of a plant or daemon config file"},
      {"max_csv_columns", [](L& l) { return &l.max_csv_columns; }, {.min = 1, .max = 1e7, .whole = true},
       "columns of a recording's header"},
      {"max_csv_bytes", [](L& l) { return &l.max_csv_bytes; }, {.min = 1, .max = 0x1p50, .whole = true},
       "bytes of a recording read at once"},
  };
  return rows;
}

std::string set_limit(Limits& limits, const std::string& key, double value) {
  for (const FieldRow<Limits>& row : Limits::fields()) {
    if (key != row.key) continue;
    if (!row.range.contains(value)) {
      char text[160];
      std::snprintf(text, sizeof text, "expected a whole number in %.0f..%.0f for %s", row.range.min, row.range.max,
                    row.key);
      return text;
    }
    std::visit(
        [&](auto* p) {
          using T = std::remove_pointer_t<decltype(p)>;
          if constexpr (std::is_arithmetic_v<T>) *p = static_cast<T>(value);
        },
        row.ref(limits));
    return "";
  }
  std::string known;
  for (const FieldRow<Limits>& row : Limits::fields()) known += (known.empty() ? "" : ", ") + std::string(row.key);
  return "no cap named " + key + " (known: " + known + ")";
}

}  // namespace mpm::config
