#include "config/json_text.hpp"

#include <cmath>
#include <cstdio>

#include "config/text_escape.hpp"

namespace mpm::config {

namespace {

// JSON's escapes: quote, backslash, \n and \t by name, the other control
// characters as \u00XX.
const EscapeTable& json_escapes() {
  static const EscapeTable table = [] {
    EscapeTable t;
    for (std::size_t c = 0; c < 0x20; ++c) {
      char b[8];
      std::snprintf(b, sizeof b, "\\u%04x", static_cast<unsigned>(c));
      t[c] = b;
    }
    t['"'] = "\\\"";
    t['\\'] = "\\\\";
    t['\n'] = "\\n";
    t['\t'] = "\\t";
    return t;
  }();
  return table;
}

}  // namespace

// Built by append: GCC 12 warns falsely (-Wrestrict) on "literal" + string.
std::string json_string(const std::string& s) {
  std::string o = "\"";
  o += escaped(s, json_escapes());
  o += '"';
  return o;
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
