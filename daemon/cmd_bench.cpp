// `mpm bench [--json] [--quick]`: runs `mpm-bench` (bench/mpm_bench_main.cpp),
// the program beside this one, with the same arguments. The benchmarks are a
// program of their own so that nothing of them (their malloc-counting
// allocator least of all) is linked into `mpm`.
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "daemon/command.hpp"

namespace mpm {
namespace {

// The folder of this executable ("" when /proc/self/exe cannot be read).
std::string own_folder() {
  std::vector<char> path(4096);
  const ssize_t n = ::readlink("/proc/self/exe", path.data(), path.size() - 1);
  if (n <= 0) return "";
  const std::string exe(path.data(), static_cast<std::size_t>(n));
  return exe.substr(0, exe.find_last_of('/'));
}

int run_bench(int argc, char** argv) {
  const std::string program = own_folder() + "/mpm-bench";
  if (::access(program.c_str(), X_OK) != 0) {
    std::fprintf(stderr, "mpm bench: no %s (built with MPM_BUILD_BENCH=OFF?)\n", program.c_str());
    return 1;
  }
  std::vector<char*> args;
  args.push_back(const_cast<char*>("mpm-bench"));
  for (int i = 1; i < argc; ++i) args.push_back(argv[i]);
  args.push_back(nullptr);
  ::execv(program.c_str(), args.data());
  std::fprintf(stderr, "mpm bench: cannot run %s: %s\n", program.c_str(), std::strerror(errno));
  return 1;
}

const bool registered = register_command({"bench", "measure the monitor's speed, memory and latency here (runs mpm-bench)", &run_bench});

}  // namespace
}  // namespace mpm
