#include "config/text_escape.hpp"

namespace mpm::config {

std::string escaped(const std::string& s, const EscapeTable& table) {
  std::string o;
  o.reserve(s.size());
  for (const char c : s) {
    const std::string& escape = table[static_cast<unsigned char>(c)];
    if (escape.empty()) {
      o += c;
    } else {
      o += escape;
    }
  }
  return o;
}

}  // namespace mpm::config
