// Logging to stderr in the form journald understands: one line per message,
// prefixed with the syslog priority "<N>" (systemd strips it and sets the
// PRIORITY field; SyslogLevelPrefix= is on by default). No timestamps: the
// journal adds its own. A line is written with one call, so lines from two
// threads never interleave.
#pragma once

#include <cstdarg>
#include <cstddef>
#include <functional>
#include <string_view>

namespace mpm::log {

enum class Level { kError = 3, kWarning = 4, kNotice = 5, kInfo = 6, kDebug = 7 };

// Where lines go; stderr by default. Tests replace it to count lines.
using Sink = std::function<void(Level, std::string_view)>;
void set_sink(Sink sink);  // empty = stderr
void set_prefix_levels(bool on);  // "<N>" prefixes (default on)

// Copies `n` bytes of `in` to `out` (capacity bytes, NUL-terminated) with
// every control character (below 0x20, and 0x7f) written as \xNN; stops
// early rather than overflow. Returns the length written. Every log line
// passes through it.
std::size_t escape_controls(const char* in, std::size_t n, char* out, std::size_t capacity) noexcept;

void write(Level level, const char* format, ...) __attribute__((format(printf, 2, 3)));
void vwrite(Level level, const char* format, std::va_list args);

}  // namespace mpm::log
