// The paper's case studies (Sec. 4), simulated under the MPC with fixed
// seeds: assertions on the located channels, not on exact numbers.
#include <algorithm>

#include <gtest/gtest.h>

#include "daemon/paper_cases.hpp"

namespace mpm {
namespace {

std::size_t samples_of(const std::string& scenario) {
  for (const auto& pc : paper_cases())
    if (scenario == pc.scenario) return pc.samples;
  ADD_FAILURE() << "no paper case " << scenario;
  return 0;
}

MonitorSettings paper_settings() {
  MonitorSettings s;
  s.forgetting = 1.0;  // whole record, as the paper's batch analysis
  return s;
}

bool contains(const std::vector<Channel>& cs, Channel c) { return std::find(cs.begin(), cs.end(), c) != cs.end(); }

class PaperCaseTest : public ::testing::TestWithParam<std::uint64_t> {};

TEST_P(PaperCaseTest, NoMismatchFlagsNoLoop) {
  const auto r = run_paper_case("wood-berry-nominal", GetParam(), samples_of("wood-berry-nominal"), paper_settings());
  EXPECT_FALSE(r.diverging);
  EXPECT_TRUE(r.located.empty());
  for (std::size_t j = 0; j < 2; ++j) EXPECT_LT(r.monitor.loop(j).lr_joint, r.monitor.joint_raise_threshold());
}

TEST_P(PaperCaseTest, G21GainIsLocatedAtU1ToY2Only) {
  const auto r = run_paper_case("wood-berry-g21-gain", GetParam(), samples_of("wood-berry-g21-gain"), paper_settings());
  EXPECT_TRUE(contains(r.located, {1, 0}));
  EXPECT_FALSE(contains(r.located, {1, 1}));
  EXPECT_FALSE(contains(r.located, {0, 0}));
  EXPECT_FALSE(contains(r.located, {0, 1}));
}

TEST_P(PaperCaseTest, G21AndG12AreBothLocated) {
  const auto r = run_paper_case("wood-berry-g21-g12", GetParam(), samples_of("wood-berry-g21-g12"), paper_settings());
  EXPECT_TRUE(contains(r.located, {1, 0}));
  EXPECT_TRUE(contains(r.located, {0, 1}));
  EXPECT_EQ(r.located.size(), 2u);
}

TEST_P(PaperCaseTest, QuadTankG23HigherOrderIsLocated) {
  const auto r = run_paper_case("quad-tank-g23-order", GetParam(), samples_of("quad-tank-g23-order"), paper_settings());
  EXPECT_FALSE(r.diverging);
  EXPECT_EQ(r.located, (std::vector<Channel>{{1, 2}}));
}

TEST_P(PaperCaseTest, QuadTankG33ZeroBecomingNonzeroIsLocated) {
  const auto r = run_paper_case("quad-tank-g33-zero", GetParam(), samples_of("quad-tank-g33-zero"), paper_settings());
  EXPECT_FALSE(r.diverging);
  EXPECT_EQ(r.located, (std::vector<Channel>{{2, 2}}));
}

TEST_P(PaperCaseTest, QuadTankG32IntegratorIsReportedUnstableNotAnalysed) {
  const auto r = run_paper_case("quad-tank-g32-integrator", GetParam(), samples_of("quad-tank-g32-integrator"), paper_settings());
  EXPECT_TRUE(r.diverging);
  EXPECT_TRUE(r.monitor.loop(2).diverging);
  EXPECT_TRUE(r.located.empty());
}

INSTANTIATE_TEST_SUITE_P(Seeds, PaperCaseTest, ::testing::Values(1u, 2u, 3u));

}  // namespace
}  // namespace mpm
