#include "config/output_file.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>

#include <sys/stat.h>

#include "config/file_text.hpp"
#include "config/plant_loader.hpp"

namespace mpm::config {

void refuse_input_as_output(const std::string& out, const std::vector<std::string>& inputs) {
  struct stat target {};
  if (::stat(out.c_str(), &target) != 0) return;  // not there yet: cannot be an input
  for (const std::string& in : inputs) {
    struct stat source {};
    if (::stat(in.c_str(), &source) != 0) continue;
    if (source.st_dev == target.st_dev && source.st_ino == target.st_ino)
      throw ConfigError(out + ": is the input " + in +
                        ": refusing to overwrite an input (choose another output path)");
  }
}

void write_output_file(const std::string& path, std::string_view text) {
  detail::write_file(path, text);
}

void write_stdout(std::string_view text) {
  std::clearerr(stdout);
  const std::size_t put = std::fwrite(text.data(), 1, text.size(), stdout);
  if (put != text.size() || std::fflush(stdout) != 0 || std::ferror(stdout))
    throw ConfigError(std::string("standard output: write failed: ") + std::strerror(errno));
}

}  // namespace mpm::config
