// Whole-file reading and writing with errors that name the file. Internal to
// config/.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace mpm::config::detail {

// Reads the whole file in one go (recordings can be large; one read is far
// faster than line-by-line streams). Only a regular file is read: a device
// (/dev/zero), a FIFO or a directory is refused before the first byte, and a
// file larger than `max_bytes` is refused (its size is checked by fstat and
// the read itself stops after max_bytes + 1). Throws ConfigError naming the
// path.
std::string read_file(const std::string& path, std::uint64_t max_bytes);

// Writes `text` to `path`, replacing it. Throws ConfigError naming the path.
void write_file(const std::string& path, std::string_view text);

}  // namespace mpm::config::detail
