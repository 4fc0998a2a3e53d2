#include "config/limits.hpp"

#include <cmath>
#include <cstdio>

namespace mpm::config {

const std::vector<LimitRow>& limit_rows() {
  // The upper ends keep every cap a number the loaders can still handle
  // (sizes that fit in memory, delays a diagnosis can scan).
  static const std::vector<LimitRow> rows = {
      {"max_inputs", 1, 10000, [](Limits& l, double v) { l.max_inputs = static_cast<std::size_t>(v); }},
      {"max_outputs", 1, 10000, [](Limits& l, double v) { l.max_outputs = static_cast<std::size_t>(v); }},
      {"max_poly_length", 1, 100000, [](Limits& l, double v) { l.max_poly_length = static_cast<std::size_t>(v); }},
      {"max_delay_samples", 0, 1e7, [](Limits& l, double v) { l.max_delay_samples = static_cast<int>(v); }},
      {"max_yaml_bytes", 1, 1ull << 40, [](Limits& l, double v) { l.max_yaml_bytes = static_cast<std::uint64_t>(v); }},
      {"max_csv_columns", 1, 1e7, [](Limits& l, double v) { l.max_csv_columns = static_cast<std::size_t>(v); }},
      {"max_csv_bytes", 1, 1ull << 50, [](Limits& l, double v) { l.max_csv_bytes = static_cast<std::uint64_t>(v); }},
  };
  return rows;
}

std::string set_limit(Limits& limits, const std::string& key, double value) {
  for (const LimitRow& row : limit_rows()) {
    if (key != row.key) continue;
    if (!(value >= row.min && value <= row.max && value == std::floor(value))) {
      char text[160];
      std::snprintf(text, sizeof text, "expected a whole number in %.0f..%.0f for %s", row.min, row.max, row.key);
      return text;
    }
    row.set(limits, value);
    return "";
  }
  std::string known;
  for (const LimitRow& row : limit_rows()) known += (known.empty() ? "" : ", ") + std::string(row.key);
  return "no cap named " + key + " (known: " + known + ")";
}

}  // namespace mpm::config
