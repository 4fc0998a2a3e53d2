// Whether a message (an error, a log, a report) mentions what it must: one
// assertion for a list of fragments, whose failure names each missing one
// and shows the whole text.
#pragma once

#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace mpm::test {

// EXPECT_TRUE(mentions(e, {"mpmd.yaml:4:", "monitor.forgeting"})) << context;
inline ::testing::AssertionResult mentions(const std::string& text, const std::vector<std::string>& fragments) {
  std::string missing;
  for (const std::string& fragment : fragments)
    if (text.find(fragment) == std::string::npos) missing += " '" + fragment + "'";
  if (missing.empty()) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "missing" << missing << " in: " << text;
}

}  // namespace mpm::test
