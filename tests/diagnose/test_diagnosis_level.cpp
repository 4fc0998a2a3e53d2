// The diagnosis' family-wise false-alarm level (Settings::alpha, `mpm
// diagnose --alpha`): on records without mismatch the share that get any
// finding stays within the level, and a higher level buys the power to
// name weaker mismatches (the trade-off docs/method.md measures on the
// randomised benchmark).
#include <cstddef>
#include <cstdio>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "core/diagnosis.hpp"
#include "support/diagnosis_problem.hpp"

namespace {

using mpm::DiscreteTf;
namespace dg = mpm::diagnosis;

constexpr Eigen::Index kSamples = 2000;
constexpr double kNoiseSd = 0.05;

// u steps to a level in [-1, 1] every 5 to 30 samples; the plant's gain is
// (1 + gain_change) x the model's; white disturbances as the plant file says.
// The monitor has flagged nothing, so a finding can only come from the
// structured tests.
dg::Problem gain_problem(unsigned seed, double gain_change) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, kNoiseSd);
  const Eigen::VectorXd u = mpm::test::random_steps(rng, kSamples, 1.0);
  Eigen::VectorXd residual = gain_change * mpm::test::first_order_channel(u);
  for (Eigen::Index k = 0; k < kSamples; ++k) residual(k) += noise(rng);
  Eigen::MatrixXd du(kSamples, 1);
  du.col(0) = u;
  dg::Problem p = mpm::test::one_output_problem({"u"}, std::move(du), std::move(residual),
                                               {mpm::test::first_order_model()}, DiscreteTf{{1.0}, {1.0}, 0},
                                               kNoiseSd * kNoiseSd);
  p.monitor_flag = {false};
  p.monitor_located = {{}};
  return p;
}

dg::Settings at_level(double alpha) {
  dg::Settings s;
  s.alpha = alpha;
  return s;
}

TEST(DiagnosisLevel, RecordsWithoutMismatchGetAFindingAtMostAtTheLevel) {
  // 150 matched records at the default level and at 0.2. The bounds are the
  // binomial's 99.9 % quantiles at the level (0.001 -> 2 of 150, 0.2 -> 46):
  // a level the tests did not hold would show as more. The design's bound is
  // 2.1 x the level (two looks and the monitor's verdict); on these open-loop
  // records with white disturbances the level itself holds.
  constexpr unsigned kRecords = 150;
  int at_default = 0, at_fifth = 0;
  for (unsigned seed = 1; seed <= kRecords; ++seed) {
    at_default += !dg::diagnose(gain_problem(seed, 0.0)).findings.empty();
    at_fifth += !dg::diagnose(gain_problem(seed, 0.0), at_level(0.2)).findings.empty();
  }
  EXPECT_LE(at_default, 2);
  EXPECT_LE(at_fifth, 46);
  EXPECT_LE(at_default, at_fifth);
  std::printf("records without mismatch with a finding: %d of %u at the default level, %d at 0.2\n", at_default,
              kRecords, at_fifth);
}

TEST(DiagnosisLevel, AHigherLevelNamesWeakerGains) {
  // A gain 0.8 % off: near what the default level can tell from noise in
  // 2000 samples. Wherever the default level names the gain, 0.1 names it
  // too, and 0.1 names it on more records. (At 0.1 a wrong word is no
  // longer rare: the level is what the caller accepts.)
  const auto names_gain = [](const dg::Result& r) {
    for (const auto& f : r.findings)
      if (f.physics == "gain") return true;
    return false;
  };
  int named_default = 0, named_tenth = 0;
  for (unsigned seed = 1; seed <= 30; ++seed) {
    const bool strict = names_gain(dg::diagnose(gain_problem(seed, 0.008)));
    const bool loose = names_gain(dg::diagnose(gain_problem(seed, 0.008), at_level(0.1)));
    if (strict) {
      EXPECT_TRUE(loose) << "seed " << seed;
    }
    named_default += strict;
    named_tenth += loose;
  }
  EXPECT_GT(named_tenth, named_default);
  std::printf("gain 0.8 %% off named on %d of 30 records at the default level, %d at 0.1\n", named_default, named_tenth);
}

}  // namespace
