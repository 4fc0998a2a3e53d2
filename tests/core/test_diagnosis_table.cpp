// The physics words and the hypothesis table: one spelling per word, the
// same list as formats.md section 3, and a table row (with a fit and a
// sentence) for every word but the monitor's fallback.
#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "core/diagnosis_physics.hpp"
#include "core/diagnosis_table.hpp"

using namespace mpm::diagnosis;

TEST(DiagnosisPhysics, EveryWordRoundTripsAndIsSpelledOnce) {
  std::set<std::string> spelled;
  for (Physics p : kAllPhysics) {
    const std::string w(word(p));
    EXPECT_FALSE(w.empty());
    EXPECT_TRUE(spelled.insert(w).second) << "spelled twice: " << w;
    ASSERT_TRUE(physics_from_word(w).has_value()) << w;
    EXPECT_EQ(*physics_from_word(w), p) << w;
  }
  EXPECT_FALSE(physics_from_word("Gain").has_value());
  EXPECT_FALSE(physics_from_word("").has_value());
  EXPECT_FALSE(physics_from_word("gain ").has_value());
}

TEST(DiagnosisPhysics, WordsAreFormatsMdVocabulary) {
  // The words of formats.md's physics table: its rows "| `word` | meaning |".
  std::ifstream in(std::string(MPM_SOURCE_DIR) + "/docs/formats.md");
  ASSERT_TRUE(in) << "docs/formats.md";
  std::set<std::string> documented;
  std::string line;
  bool in_table = false;
  while (std::getline(in, line)) {
    if (line.rfind("| physics | meaning |", 0) == 0) in_table = true;
    else if (in_table && line.rfind("| `", 0) == 0) documented.insert(line.substr(3, line.find('`', 3) - 3));
    else if (in_table && line.rfind("|---", 0) != 0) in_table = false;
  }
  std::set<std::string> ours;
  for (Physics p : kAllPhysics) ours.insert(std::string(word(p)));
  EXPECT_EQ(documented, ours);
}

TEST(DiagnosisTable, EveryWordButTheFallbackHasARowWithAFitAndASentence) {
  std::set<Physics> covered;
  for (const Hypothesis& h : hypothesis_table()) {
    covered.insert(h.physics);
    EXPECT_NE(h.physics, Physics::other) << "`other` is the monitor's fallback, not a hypothesis";
    EXPECT_NE(h.applies, nullptr) << word(h.physics);
    EXPECT_NE(h.fit, nullptr) << word(h.physics);
    EXPECT_NE(h.sentence, nullptr) << word(h.physics);
    EXPECT_GE(h.params, 0) << word(h.physics);
    // Only a recorded signal (not moved by the controller), a changed noise
    // model itself and a sensor lag (partly a change of the noise it sees:
    // it competes with the changed noise model in the selection instead)
    // skip the test beyond a changed disturbance model.
    const bool exempt = h.physics == Physics::unmodeled_input || h.physics == Physics::disturbance_model ||
                        h.physics == Physics::sensor_dynamics;
    EXPECT_EQ(h.gate == Gate::held_out, exempt) << word(h.physics);
  }
  for (Physics p : kAllPhysics) {
    if (p == Physics::other) continue;
    EXPECT_TRUE(covered.count(p)) << "no row for " << word(p);
  }
}

TEST(DiagnosisTable, ParameterCountScalesWithItsUnit) {
  for (const Hypothesis& h : hypothesis_table()) {
    const int one = h.count(1, 1);
    EXPECT_EQ(one, h.params) << word(h.physics);
    EXPECT_EQ(h.count(3, 2), h.per == Per::channel ? 3 * h.params : h.per == Per::output ? 2 * h.params : h.params)
        << word(h.physics);
  }
}
