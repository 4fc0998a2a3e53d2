#include "config/json_text.hpp"

#include <cmath>
#include <cstdio>

namespace mpm::config {

std::string json_string(const std::string& s) {
  std::string o = "\"";
  for (char c : s) {
    switch (c) {
      case '"': o += "\\\""; break;
      case '\\': o += "\\\\"; break;
      case '\n': o += "\\n"; break;
      case '\t': o += "\\t"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char b[8];
          std::snprintf(b, sizeof b, "\\u%04x", static_cast<unsigned>(static_cast<unsigned char>(c)));
          o += b;
        } else {
          o += c;
        }
    }
  }
  return o + "\"";
}

std::string json_number(double v, int digits) {
  if (!std::isfinite(v)) return "null";
  char b[48];
  std::snprintf(b, sizeof b, "%.*g", digits, v);
  return b;
}

std::string json_number_list(const std::vector<double>& v, int digits) {
  std::string o = "[";
  for (std::size_t k = 0; k < v.size(); ++k) {
    if (k) o += ", ";
    o += json_number(v[k], digits);
  }
  return o + "]";
}

}  // namespace mpm::config
