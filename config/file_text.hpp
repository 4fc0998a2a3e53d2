// Whole-file reading and writing with errors that name the file. Internal to
// config/.
#pragma once

#include <string>
#include <string_view>

namespace mpm::config::detail {

// Reads the whole file in one go (recordings can be large; one read is far
// faster than line-by-line streams). Throws ConfigError naming the path.
std::string read_file(const std::string& path);

// Writes `text` to `path`, replacing it. Throws ConfigError naming the path.
void write_file(const std::string& path, std::string_view text);

}  // namespace mpm::config::detail
