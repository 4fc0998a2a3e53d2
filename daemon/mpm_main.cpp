// `mpm <command> [options]`: dispatches to the self-registered subcommands.
#include <cstdio>
#include <cstring>
#include <string>

#include "daemon/command.hpp"

namespace mpm {

std::vector<Command>& registry() {
  static std::vector<Command> all;
  return all;
}

bool register_command(const Command& command) {
  registry().push_back(command);
  return true;
}

const std::vector<Command>& commands() { return registry(); }

}  // namespace mpm

namespace {

void usage(std::FILE* out) {
  std::fprintf(out, "usage: mpm <command> [options]   (mpm <command> --help for its options; mpm --version)\n\ncommands:\n");
  for (const auto& c : mpm::commands()) std::fprintf(out, "  %-10s %s\n", c.name, c.summary);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    usage(stderr);
    return 2;
  }
  if (!std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h") || !std::strcmp(argv[1], "help")) {
    usage(stdout);
    return 0;
  }
  if (!std::strcmp(argv[1], "--version")) {
    std::printf("mpm %s\n", MPM_VERSION);
    return 0;
  }
  for (const auto& c : mpm::commands()) {
    if (std::strcmp(argv[1], c.name) == 0) return c.run(argc - 1, argv + 1);
  }
  std::fprintf(stderr, "mpm: unknown command '%s'\n", argv[1]);
  usage(stderr);
  return 2;
}
