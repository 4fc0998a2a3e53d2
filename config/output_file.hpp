// Writing a command's result safely: never over one of its inputs, and never
// silently losing a write error (a full disk, /dev/full, a closed pipe).
#pragma once

#include <string>
#include <string_view>
#include <vector>

namespace mpm::config {

// Throws ConfigError when `out` is the same file as one of `inputs` (same
// device and inode, so a symlink or another spelling of the path is caught
// too). A path that does not exist yet is no input.
void refuse_input_as_output(const std::string& out, const std::vector<std::string>& inputs);

// Writes `text` to `path` (replacing it); throws ConfigError on any error,
// including one reported only when the file is closed.
void write_output_file(const std::string& path, std::string_view text);

// Writes `text` to standard output and flushes it; throws ConfigError when
// the stream reports an error (e.g. stdout is /dev/full).
void write_stdout(std::string_view text);

}  // namespace mpm::config
