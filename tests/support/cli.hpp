// Helpers for tests that drive the built `mpm` binary: where it is, a
// temporary file name, running a command quietly, reading a file whole.
#pragma once

#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

namespace mpm::test {

inline const std::string kMpm = std::string(MPM_BINARY_DIR) + "/daemon/mpm";

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

}  // namespace mpm::test
