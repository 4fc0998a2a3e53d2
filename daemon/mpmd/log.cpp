#include "daemon/mpmd/log.hpp"

#include <cstdio>
#include <mutex>

namespace mpm::log {
namespace {

std::mutex& sink_mutex() {
  static std::mutex m;
  return m;
}
Sink& current_sink() {
  static Sink sink;
  return sink;
}
bool& prefix_levels() {
  static bool on = true;
  return on;
}

}  // namespace

void set_sink(Sink sink) {
  std::lock_guard lock(sink_mutex());
  current_sink() = std::move(sink);
}

void set_prefix_levels(bool on) {
  std::lock_guard lock(sink_mutex());
  prefix_levels() = on;
}

std::size_t escape_controls(const char* in, std::size_t n, char* out, std::size_t capacity) noexcept {
  static constexpr char kHex[] = "0123456789abcdef";
  std::size_t o = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const auto c = static_cast<unsigned char>(in[i]);
    if (c >= 0x20 && c != 0x7f) {
      if (o + 1 >= capacity) break;
      out[o++] = static_cast<char>(c);
      continue;
    }
    if (o + 4 >= capacity) break;
    out[o++] = '\\';
    out[o++] = 'x';
    out[o++] = kHex[c >> 4];
    out[o++] = kHex[c & 0xf];
  }
  if (capacity > 0) out[o] = '\0';
  return o;
}

void vwrite(Level level, const char* format, std::va_list args) {
  char raw[1024];
  int n = std::vsnprintf(raw, sizeof raw, format, args);
  if (n < 0) return;
  if (static_cast<std::size_t>(n) >= sizeof raw) n = sizeof raw - 1;  // truncated
  // Strings from the wire (controller ids, names) go into log lines: a
  // newline in one must not start a journald line of its own ("\n<0>..."
  // would be an emergency), so every control character becomes \xNN.
  char line[4 * sizeof raw];
  const std::size_t length = escape_controls(raw, static_cast<std::size_t>(n), line, sizeof line);
  std::lock_guard lock(sink_mutex());
  if (current_sink()) {
    current_sink()(level, std::string_view(line, length));
    return;
  }
  if (prefix_levels()) {
    std::fprintf(stderr, "<%d>%s\n", static_cast<int>(level), line);
  } else {
    std::fprintf(stderr, "%s\n", line);
  }
}

void write(Level level, const char* format, ...) {
  std::va_list args;
  va_start(args, format);
  vwrite(level, format, args);
  va_end(args);
}

}  // namespace mpm::log
