#include "config/file_text.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>

#include <sys/stat.h>

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

std::string read_file(const std::string& path, std::uint64_t max_bytes) {
  File file(std::fopen(path.c_str(), "rb"));
  if (!file) fail(path, "open", errno);
  struct stat info {};
  if (::fstat(::fileno(file.get()), &info) != 0) fail(path, "inspect", errno);
  if (!S_ISREG(info.st_mode))
    throw ConfigError(path + ": not a regular file (a device, FIFO or directory is not read)");
  const auto too_big = [&] {
    return ConfigError(path + ": file is larger than the limit of " + std::to_string(max_bytes) +
                       " bytes");
  };
  if (static_cast<std::uint64_t>(info.st_size) > max_bytes) throw too_big();
  std::string text;
  text.reserve(static_cast<std::size_t>(info.st_size));
  char buffer[1 << 16];
  // The size from fstat is a hint: the file may grow while it is read, so the
  // read itself stops one byte past the limit.
  for (;;) {
    const std::size_t got = std::fread(buffer, 1, sizeof buffer, file.get());
    text.append(buffer, got);
    if (text.size() > max_bytes) throw too_big();
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
