// The README's dependency rules (Layout: "Dependencies point one way"),
// checked on the includes of every source file: core ← config ← sim ←
// daemon, transport ← daemon/mpmd; settings/ (plain data: the transport
// settings) is a leaf every layer may name; nothing of the product includes
// bench/ or tests/; the generated wire types are the transport's own.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace {

namespace fs = std::filesystem;

// What each folder of the product may include (by the first part of the
// path: "core/x.hpp" is core). bench/ and tests/ may include anything.
const std::map<std::string, std::set<std::string>> kAllowed = {
    {"core", {"core"}},
    {"settings", {"settings"}},
    {"config", {"core", "settings", "config"}},
    {"sim", {"core", "settings", "config", "sim"}},
    {"transport", {"settings", "transport"}},
    {"daemon", {"core", "settings", "config", "sim", "transport", "daemon"}},
};

// Known breaches, each removed by the change that ends it (the test fails
// when one no longer occurs, so the list cannot go stale). None at present.
const std::set<std::pair<std::string, std::string>> kKnownBreaches = {};

struct Include {
  std::string file;    // relative to the source tree
  std::string target;  // as written between the quotes or angle brackets
  bool angled;
};

std::vector<Include> includes_under(const std::string& folder) {
  std::vector<Include> out;
  const fs::path root = MPM_SOURCE_DIR;
  const std::regex include_line(R"(^\s*#\s*include\s*([<"])([^>"]+)[>"])");
  for (const auto& entry : fs::recursive_directory_iterator(root / folder)) {
    const std::string ext = entry.path().extension().string();
    if (!entry.is_regular_file() || (ext != ".cpp" && ext != ".hpp" && ext != ".h")) continue;
    std::ifstream in(entry.path());
    std::smatch m;
    for (std::string line; std::getline(in, line);) {
      if (std::regex_search(line, m, include_line))
        out.push_back({fs::relative(entry.path(), root).string(), m[2].str(), m[1].str() == "<"});
    }
  }
  return out;
}

const std::set<std::string> kProjectFolders = {"core", "settings", "config", "sim", "transport", "daemon", "bench", "tests"};

TEST(DependencyRules, EveryFolderIncludesOnlyWhatTheReadmeAllows) {
  std::set<std::pair<std::string, std::string>> breaches_seen;
  int project_includes = 0;
  for (const auto& [folder, allowed] : kAllowed) {
    for (const Include& inc : includes_under(folder)) {
      if (inc.angled) {
        // lcm-gen's and idlc's types: only the transport's adapters see them.
        const bool generated = inc.target.rfind("mpm_lcm/", 0) == 0 || inc.target == "mpm.h";
        EXPECT_TRUE(!generated || folder == "transport") << inc.file << " includes <" << inc.target << ">";
        continue;
      }
      const std::string top = inc.target.substr(0, inc.target.find('/'));
      if (!kProjectFolders.count(top)) continue;  // a header of the same folder, by its own name
      ++project_includes;
      if (allowed.count(top)) continue;
      if (kKnownBreaches.count({inc.file, inc.target})) {
        breaches_seen.insert({inc.file, inc.target});
        continue;
      }
      ADD_FAILURE() << inc.file << " includes \"" << inc.target << "\": " << folder << " may include only "
                    << ::testing::PrintToString(allowed) << " (README, Layout)";
    }
  }
  EXPECT_GT(project_includes, 100);  // the files were found and read
  EXPECT_EQ(breaches_seen, kKnownBreaches) << "a known breach is gone: remove it from kKnownBreaches";
}

// core/ is two libraries (core/CMakeLists.txt): the offline diagnosis
// (diagnosis*, decussation*) builds on the real-time monitor, never the
// reverse, so mpmd's per-sample path links no diagnosis code.
bool in_diagnosis_library(const std::string& path) {
  const std::string name = fs::path(path).filename().string();
  return name.rfind("diagnosis", 0) == 0 || name.rfind("decussation", 0) == 0;
}

TEST(DependencyRules, TheMonitorLibraryIncludesNothingOfTheDiagnosis) {
  int monitor_includes = 0;
  for (const Include& inc : includes_under("core")) {
    if (inc.angled || in_diagnosis_library(inc.file) || inc.target.rfind("core/", 0) != 0) continue;
    ++monitor_includes;
    EXPECT_FALSE(in_diagnosis_library(inc.target))
        << inc.file << " includes \"" << inc.target << "\": the monitor library (mpm_core) may not use the diagnosis (mpm_diagnosis)";
  }
  EXPECT_GT(monitor_includes, 20);  // the monitor's files were found and read
}

}  // namespace
