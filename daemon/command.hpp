// Subcommands of the `mpm` tool register themselves here, one file each
// (cmd_<name>.cpp), so the dispatcher in mpm_main.cpp never changes when a
// command is added:
//
//   static const bool registered = mpm::register_command(
//       {"simulate", "run the closed-loop simulator and write a recording", &run_simulate});
//
// A command gets argv after its name (argv[0] = the command name) and returns
// the process exit code: 0 success, 1 runtime failure, 2 usage error.
#pragma once

#include <string>
#include <vector>

namespace mpm {

struct Command {
  const char* name;
  const char* summary;
  int (*run)(int argc, char** argv);
};

bool register_command(const Command& command);
const std::vector<Command>& commands();

}  // namespace mpm
