// Helpers for tests that drive the built `mpm` binary: where it and the
// plant files are, a temporary file name, running a command quietly,
// reading a file whole.
#pragma once

#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

namespace mpm::test {

inline const std::string kMpm = std::string(MPM_BINARY_DIR) + "/daemon/mpm";

// A plant file of the source tree's config/ folder.
inline std::string config_file(const std::string& name) { return std::string(MPM_SOURCE_DIR) + "/config/" + name; }

// A path in the test's temporary folder, `prefix` + `name`.
inline std::string tmp_path(const std::string& prefix, const std::string& name) {
  return (::testing::TempDir().empty() ? std::string("/tmp/") : ::testing::TempDir()) + prefix + name;
}

// Runs `cmd` with its output discarded; the std::system status.
inline int run_quietly(const std::string& cmd) { return std::system((cmd + " >/dev/null 2>&1").c_str()); }

inline std::string read_file(const std::string& path) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

// tmp_path with the running test's name in it: ctest runs each test of a
// file in a process of its own, in parallel, so names must not collide.
inline std::string per_test_tmp_path(const std::string& prefix, const std::string& name) {
  return tmp_path(prefix + ::testing::UnitTest::GetInstance()->current_test_info()->name() + "_", name);
}

struct CliRun {
  int exit_code = -1;  // -1: did not exit normally
  std::string out, err;
};

// Runs `cmd`, capturing its exit code, standard output and standard error
// (through files named from `prefix`, per test).
inline CliRun run_captured(const std::string& cmd, const std::string& prefix) {
  const std::string out = per_test_tmp_path(prefix, "stdout.txt"), err = per_test_tmp_path(prefix, "stderr.txt");
  const int status = std::system((cmd + " >" + out + " 2>" + err).c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, read_file(out), read_file(err)};
}

}  // namespace mpm::test
