#include "config/file_text.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>

#include "config/plant_loader.hpp"

namespace mpm::config::detail {
namespace {

struct FileCloser {
  void operator()(std::FILE* f) const noexcept { std::fclose(f); }
};
using File = std::unique_ptr<std::FILE, FileCloser>;

[[noreturn]] void fail(const std::string& path, const char* action, int error) {
  throw ConfigError(path + ": cannot " + action + " file: " + std::strerror(error));
}

}  // namespace

std::string read_file(const std::string& path) {
  File file(std::fopen(path.c_str(), "rb"));
  if (!file) fail(path, "open", errno);
  std::string text;
  char buffer[1 << 16];
  // Grow by fread chunks rather than trusting a size from fseek/ftell, which
  // fails for pipes and /dev/stdin-like paths.
  for (;;) {
    const std::size_t got = std::fread(buffer, 1, sizeof buffer, file.get());
    text.append(buffer, got);
    if (got < sizeof buffer) break;
  }
  if (std::ferror(file.get())) fail(path, "read", errno);
  return text;
}

void write_file(const std::string& path, std::string_view text) {
  File file(std::fopen(path.c_str(), "wb"));
  if (!file) fail(path, "create", errno);
  if (std::fwrite(text.data(), 1, text.size(), file.get()) != text.size())
    fail(path, "write", errno);
  if (std::fclose(file.release()) != 0) fail(path, "write", errno);
}

}  // namespace mpm::config::detail
