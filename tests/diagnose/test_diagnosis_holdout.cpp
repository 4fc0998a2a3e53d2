// The diagnosis library's held-out test where an effect comes in an episode:
// an input that crosses a limit the model does not know only once, in a
// stretch the fit blocks hold. Its correction is zero on the held-out part,
// where even an exact one would give z_hold about 0: the held-out test is
// uninformative there, not failed, and the fit-part test decides. And the
// other way round: a changed disturbance model whose evidence the held-out
// blocks happen to hold more of than the fit blocks is named on the two
// parts' evidence pooled, as every other candidate is.
#include <algorithm>
#include <cstddef>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/chi_square.hpp"
#include "core/diagnosis.hpp"
#include "core/diagnosis_context.hpp"
#include "support/diagnosis_problem.hpp"

namespace {

using mpm::DiscreteTf;
namespace dg = mpm::diagnosis;

using mpm::test::first_order_channel;
using mpm::test::random_steps;

// u steps within [-1, 1], except once, from `episode` for 80 samples, at
// 2.5; the plant's actuator stops at 1.2, which only that episode reaches.
// White disturbances of sd 0.05, as the plant file says (N = 1).
dg::Problem episode_problem(unsigned seed, Eigen::Index episode) {
  const Eigen::Index n = 3000;
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.05);
  Eigen::VectorXd u = random_steps(rng, n, 1.0), plant_u(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    if (k >= episode && k < episode + 80) u(k) = 2.5;
    plant_u(k) = std::min(u(k), 1.2);
  }
  Eigen::VectorXd residual = first_order_channel(plant_u) - first_order_channel(u);
  for (Eigen::Index k = 0; k < n; ++k) residual(k) += noise(rng);
  Eigen::MatrixXd du(n, 1);
  du.col(0) = u;
  return mpm::test::one_output_problem({"u"}, std::move(du), std::move(residual), {mpm::test::first_order_model()},
                                      DiscreteTf{{1.0}, {1.0}, 0}, 0.05 * 0.05);
}

std::string describe(const dg::Result& r) {
  std::string s;
  for (const auto& f : r.findings) s += f.physics + " (" + f.summary + "); ";
  return s.empty() ? "no findings" : s;
}

TEST(DiagnosisHoldout, LimitReachedOnlyInAFittedEpisodeIsNamed) {
  // The episode lies in the first block (fitted; the held-out blocks are the
  // third, sixth and ninth tenths of the record).
  for (unsigned seed : {1u, 2u, 3u}) {
    const dg::Result r = dg::diagnose(episode_problem(seed, 120));
    const std::string what = "seed " + std::to_string(seed) + ": " + describe(r);
    ASSERT_EQ(r.findings.size(), 1u) << what;
    EXPECT_EQ(r.findings.front().physics, "saturation") << what;
  }
}

// Settings::holdout_phase moves the held-out third of the ten blocks: under
// phase p the held-out samples are those of the blocks b with b % 3 == p
// (the tenth block counted with the ninth), the three phases' held-out parts
// partition the usable samples, and the same episode in block 0 is named
// where that block is fitted and not where it is held out (then the fit part
// holds no crossing of the limit to fit).
TEST(DiagnosisHoldout, ThePhaseChoosesWhichBlocksAreHeldOut) {
  ASSERT_EQ(dg::Settings{}.holdout_phase, 2);
  const dg::Problem p = episode_problem(1, 120);
  const auto n = static_cast<std::size_t>(p.residual.rows());
  std::vector<int> times_held(n, 0);
  std::size_t usable = 0;
  for (int phase = 0; phase <= 2; ++phase) {
    dg::Settings settings;
    settings.holdout_phase = phase;
    const dg::Context cx = dg::prepare(p, settings);
    const auto first = static_cast<std::size_t>(cx.seg.begin);
    ASSERT_LT(first, n / 10);
    const std::size_t block = (n - first) / 10;
    std::size_t here = 0;
    for (std::size_t k = 0; k < n; ++k) {
      ASSERT_FALSE(cx.seg.fit[k] && cx.seg.hold[k]) << k;
      if (!cx.seg.fit[k] && !cx.seg.hold[k]) continue;
      ++here;
      const bool held = static_cast<int>(std::min<std::size_t>(9, (k - first) / block) % 3) == phase;
      ASSERT_EQ(static_cast<bool>(cx.seg.hold[k]), held) << "phase " << phase << ", sample " << k;
      times_held[k] += cx.seg.hold[k];
    }
    if (phase > 0) {
      EXPECT_EQ(here, usable);
    }
    usable = here;
  }
  for (std::size_t k = 0; k < n; ++k) EXPECT_LE(times_held[k], 1) << k;
  EXPECT_EQ(static_cast<std::size_t>(std::count(times_held.begin(), times_held.end(), 1)), usable);

  for (unsigned seed : {1u, 2u})
    for (int phase = 0; phase <= 2; ++phase) {
      dg::Settings settings;
      settings.holdout_phase = phase;
      const dg::Result r = dg::diagnose(episode_problem(seed, 120), settings);
      bool saturation = false;
      for (const auto& f : r.findings) saturation = saturation || f.physics == "saturation";
      EXPECT_EQ(saturation, phase != 0) << "seed " << seed << ", phase " << phase << ": " << describe(r);
    }
}

// The plant file says the disturbances are 1 / (1 - 0.8 q^-1) white noise
// of sd 0.05; the input's channel is right, and the input moves enough that
// a sensor lag (the changed noise model's near-alias) would show on it. The
// noise pole is in fact 0.92 wherever the third, sixth and ninth tenths of the record lie (the
// held-out blocks) and 0.83 elsewhere: on the fit blocks alone the change
// is too small to pass its limit.
dg::Problem noise_problem(unsigned seed) {
  const Eigen::Index n = 4000;
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.05);
  const Eigen::VectorXd u = random_steps(rng, n, 3.0);
  Eigen::VectorXd residual(n);
  double d = 0.0;
  for (Eigen::Index k = 0; k < n; ++k) {
    const bool held_out_block = (k / (n / 10)) % 3 == dg::Settings{}.holdout_phase;
    d = (held_out_block ? 0.92 : 0.83) * d + noise(rng);
    residual(k) = d;
  }
  Eigen::MatrixXd du(n, 1);
  du.col(0) = u;
  return mpm::test::one_output_problem({"u"}, std::move(du), std::move(residual), {mpm::test::first_order_model()},
                                      DiscreteTf{{1.0}, {1.0, -0.8}, 0}, 0.05 * 0.05);
}

TEST(DiagnosisHoldout, NoiseChangeMostlyInTheHeldOutBlocksIsNamedOnPooledEvidence) {
  // The fit-part test alone, at its level with the held-out test over the
  // disturbance model's four forms: what a finding needed before the pooled
  // evidence counted for this hypothesis too.
  const dg::Settings settings;
  const auto fit_part_limit = [&](int params) {
    return mpm::chi_square_quantile_upper(settings.alpha / settings.holdout_level / 4.0, params);
  };
  int named = 0, named_below_fit_limit = 0;
  std::string all;
  for (unsigned seed = 1; seed <= 10; ++seed) {
    const dg::Result r = dg::diagnose(noise_problem(seed));
    const std::string what = "seed " + std::to_string(seed) + ": " + describe(r);
    all += what + "\n";
    for (const dg::Finding& f : r.findings) {
      // Nothing else is named: the input's channel is right.
      EXPECT_TRUE(f.physics == "disturbance_model" || f.physics == "other") << what;
      if (f.physics != "disturbance_model") continue;
      ++named;
      named_below_fit_limit += f.lr < fit_part_limit(f.params);
      EXPECT_LT(f.fit.holdout_variance_after, f.fit.holdout_variance_before) << what;
    }
  }
  EXPECT_GE(named, 6) << all;
  EXPECT_GE(named_below_fit_limit, 2) << all;
}

}  // namespace
