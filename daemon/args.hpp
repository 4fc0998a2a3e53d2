// Options of the mpm subcommands and mpm-bench, parsed by CLI11 (Debian's
// libcli11-dev): `--name value`, `--name=value` and `--flag`; every option is
// declared, anything else is a usage error. A valued option given more than
// once keeps every value (all()); get() sees the last.
//
// run_command() is the frame every command shares: --help prints the
// command's usage on stdout, --version the version, and the exit codes are
// the same for all (README, "Exit codes"; docs/man/mpm.1):
//   0 done (and --help, --version);
//   1 failed: a file that cannot be read or is invalid, a transport that
//     cannot start, a run that did not complete (the message says which);
//   2 usage error: an unknown or malformed option, a missing required one
//     (message and usage on stderr);
//   3 cannot decide: mpm diagnose had too few usable samples for its tests.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace mpm {

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

inline constexpr int kExitOk = 0;
inline constexpr int kExitFailed = 1;
inline constexpr int kExitUsage = 2;
inline constexpr int kExitUndecided = 3;

class Args {
 public:
  // valued: options that take a value; flags: options that do not (both
  // without the leading "--"). Throws UsageError with CLI11's message.
  Args(int argc, char** argv, const std::set<std::string>& valued, const std::set<std::string>& flags) {
    CLI::App app;
    app.set_help_flag();  // --help is a flag like any other (the command prints its usage)
    app.allow_extras(false);
    for (const std::string& name : valued) {
      app.add_option("--" + name, values_[name])
          ->expected(1)
          ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)
          ->allow_extra_args(false);
    }
    for (const std::string& name : flags) app.add_flag("--" + name, counts_[name]);
    try {
      app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
      throw UsageError(e.what());
    }
  }
  bool flag(const std::string& name) const {
    auto it = counts_.find(name);
    return it != counts_.end() && it->second > 0;
  }
  std::optional<std::string> get(const std::string& name) const {
    auto it = values_.find(name);
    if (it == values_.end() || it->second.empty()) return std::nullopt;
    return it->second.back();
  }
  // Every value of a repeatable option, in command-line order.
  std::vector<std::string> all(const std::string& name) const {
    auto it = values_.find(name);
    return it == values_.end() ? std::vector<std::string>{} : it->second;
  }
  std::string required(const std::string& name) const {
    auto v = get(name);
    if (!v) throw UsageError("--" + name + " is required");
    return *v;
  }
  double number(const std::string& name, double fallback) const {
    auto v = get(name);
    if (!v) return fallback;
    char* end = nullptr;
    const double x = std::strtod(v->c_str(), &end);
    if (end == v->c_str() || *end != '\0') throw UsageError("--" + name + ": expected a number, got '" + *v + "'");
    return x;
  }
  int integer(const std::string& name, int fallback) const {
    const double x = number(name, fallback);
    if (!(x >= -2147483648.0 && x <= 2147483647.0) || x != static_cast<int>(x))
      throw UsageError("--" + name + ": expected an integer");
    return static_cast<int>(x);
  }

 private:
  std::map<std::string, std::vector<std::string>> values_;
  std::map<std::string, int> counts_;
};

// One command's frame: parses the options (plus --help and --version),
// prints the usage for --help, then runs `body`. A UsageError (from parsing
// or from `body`) prints "<name>: <what>" and the usage on stderr and
// returns kExitUsage; any other exception prints "<name>: <what>" and
// returns kExitFailed. `body` returns the exit code of a completed run.
inline int run_command(const char* name, const char* usage, int argc, char** argv, std::set<std::string> valued,
                       std::set<std::string> flags, const std::function<int(const Args&)>& body) {
  flags.insert({"help", "version"});
  try {
    const Args args(argc, argv, valued, flags);
    if (args.flag("help")) {
      std::fputs(usage, stdout);
      return kExitOk;
    }
    if (args.flag("version")) {
      std::printf("%s %s\n", name, MPM_VERSION);
      return kExitOk;
    }
    return body(args);
  } catch (const UsageError& e) {
    std::fprintf(stderr, "%s: %s\n%s", name, e.what(), usage);
    return kExitUsage;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: %s\n", name, e.what());
    return kExitFailed;
  }
}

}  // namespace mpm
