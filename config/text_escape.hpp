// Escaping text for the formats we write (JSON strings, the report page's
// HTML and script): one loop over the bytes, each format's rules a table of
// what every byte becomes.
#pragma once

#include <array>
#include <string>

namespace mpm::config {

// For each byte value, the text that stands for it; empty: the byte itself.
using EscapeTable = std::array<std::string, 256>;

// `s` with every byte that has an entry in `table` replaced by that entry.
std::string escaped(const std::string& s, const EscapeTable& table);

}  // namespace mpm::config
