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

void vwrite(Level level, const char* format, std::va_list args) {
  char line[1024];
  int n = std::vsnprintf(line, sizeof line, format, args);
  if (n < 0) return;
  if (static_cast<std::size_t>(n) >= sizeof line) n = sizeof line - 1;  // truncated
  std::lock_guard lock(sink_mutex());
  if (current_sink()) {
    current_sink()(level, std::string_view(line, static_cast<std::size_t>(n)));
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
