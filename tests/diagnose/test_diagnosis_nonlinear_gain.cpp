// The diagnosis library's static-nonlinearity form (`nonlinear_gain`): a
// linear, a centred even and an odd term of the input (and each nonlinear
// term alone beside the linear one), offered only when the nonlinear terms
// are significant beyond the best linear gains (nested test). Two plain gain changes on one input whose
// level sits away from the model's operating point must stay gains (the old
// u^2 regressor took them for one column "nonlinear gain"), and an odd
// map v (1 + a |v|), which an even-only form saw as a gain, must be named.
// The nested test pools the fit part's nested LR with the held-out
// projection of the bend (beyond_nested): a bend under the fit part's own
// limit is named when the held-out blocks confirm it, and a bend the
// held-out blocks contradict is not.
#include <cmath>
#include <cstddef>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "core/chi_square.hpp"
#include "core/diagnosis_context.hpp"

namespace {

using mpm::DiscreteTf;
namespace dg = mpm::diagnosis;

const DiscreteTf kChannel{{0.1}, {1.0, -0.9}, 1};

// One input u (steps held 10 samples, level `offset` + N(0, 0.7) from the
// model's operating point), two outputs through kChannel each; the plant's
// effective input into output j is map_j(du); white noise of sd 0.05.
template <class Map1, class Map2>
dg::Problem column_problem(unsigned seed, double offset, Map1 map1, Map2 map2, bool y2_flagged) {
  const Eigen::Index n = 3000;
  std::mt19937 rng(seed);
  std::normal_distribution<double> level(offset, 0.7), noise(0.0, 0.05);
  Eigen::VectorXd du(n), v1(n), v2(n);
  double held = offset;
  for (Eigen::Index k = 0; k < n; ++k) {
    if (k % 10 == 0) held = level(rng);
    du(k) = held;
    v1(k) = map1(held);
    v2(k) = map2(held);
  }
  const auto sim = [&](const Eigen::VectorXd& x) {
    Eigen::VectorXd y = Eigen::VectorXd::Zero(n);
    for (Eigen::Index k = 2; k < n; ++k) y(k) = 0.9 * y(k - 1) + 0.1 * x(k - 1);
    return y;
  };
  const Eigen::VectorXd g = sim(du), y1 = sim(v1), y2 = sim(v2);
  dg::Problem p;
  p.inputs = {"u"};
  p.outputs = {"y1", "y2"};
  p.du = Eigen::MatrixXd(n, 1);
  p.du.col(0) = du;
  p.u_abs = p.du;
  p.residual = Eigen::MatrixXd(n, 2);
  for (Eigen::Index k = 0; k < n; ++k) {
    p.residual(k, 0) = y1(k) - g(k) + noise(rng);
    p.residual(k, 1) = y2(k) - g(k) + noise(rng);
  }
  p.nominal = {kChannel, kChannel};
  p.noise = {DiscreteTf{{1.0}, {1.0}, 0}, DiscreteTf{{1.0}, {1.0}, 0}};
  p.noise_variance = {0.05 * 0.05, 0.05 * 0.05};
  p.monitor_flag = {true, y2_flagged};
  p.monitor_located = {{0}, {0}};
  return p;
}

TEST(DiagnosisNonlinearGain, TwoGainsOnOneInputAwayFromTheOperatingPointStayGains) {
  for (unsigned seed : {1u, 2u, 3u}) {
    const dg::Result r = dg::diagnose(column_problem(
        seed, 1.5, [](double v) { return 0.75 * v; }, [](double v) { return 1.3 * v; }, true));
    std::string all;
    for (const dg::Finding& f : r.findings) all += f.physics + ": " + f.summary + "; ";
    // One gain finding over the column, a factor per channel.
    ASSERT_EQ(r.findings.size(), 1u) << "seed " << seed << ": " << all;
    const dg::Finding& f = r.findings[0];
    EXPECT_EQ(f.physics, "gain") << "seed " << seed << ": " << all;
    ASSERT_EQ(f.channels.size(), 2u) << "seed " << seed << ": " << all;
    EXPECT_NEAR(f.parameters.at("gain_factor_y1"), 0.75, 0.05) << "seed " << seed << ": " << f.summary;
    EXPECT_NEAR(f.parameters.at("gain_factor_y2"), 1.3, 0.05) << "seed " << seed << ": " << f.summary;
  }
}

TEST(DiagnosisNonlinearGain, OddStaticMapOnOneChannelIsNamed) {
  for (unsigned seed : {1u, 2u, 3u}) {
    const dg::Result r = dg::diagnose(column_problem(
        seed, 0.0, [](double v) { return v * (1.0 + 0.5 * std::abs(v)); }, [](double v) { return v; }, false));
    ASSERT_FALSE(r.findings.empty()) << "seed " << seed;
    const dg::Finding& f = r.findings.front();
    EXPECT_EQ(f.physics, "nonlinear_gain") << "seed " << seed << ": " << f.summary;
    ASSERT_EQ(f.channels.size(), 1u) << "seed " << seed << ": " << f.summary;
    EXPECT_EQ(f.channels[0].output, 0u) << "seed " << seed;
    EXPECT_GT(f.parameters.at("odd_coefficient"), 0.0) << "seed " << seed << ": " << f.summary;
    EXPECT_LT(f.fit.holdout_variance_after, f.fit.holdout_variance_before) << "seed " << seed;
    // y2 is linear and unchanged: nothing there.
    for (const dg::Finding& g : r.findings)
      for (const dg::Channel& c : g.channels) EXPECT_EQ(c.output, 0u) << "seed " << seed << ": " << g.summary;
  }
}

// A weak bend costs only its own term: as a soft saturation v / (1 + a |v|)
// (odd) or a concave map v - c v^2 (even) grows from nothing, it is named
// on y1 by the linear term and that one term before the full map (a
// parameter more per channel) beats the plain gain.
TEST(DiagnosisNonlinearGain, AWeakBendIsNamedWithItsOwnTermAlone) {
  struct Case {
    const char* name;
    double (*map)(double v, double a);
    std::string term;
    std::string absent;
  };
  const Case cases[] = {
      {"odd", [](double v, double a) { return v / (1.0 + a * std::abs(v)); }, "odd_coefficient", "even_coefficient"},
      {"even", [](double v, double a) { return v - a * v * v; }, "even_coefficient", "odd_coefficient"},
  };
  for (const Case& c : cases) {
    std::string seen;
    bool alone = false;
    for (double a = 0.005; a < 0.3 && !alone; a *= 1.25) {
      const dg::Result r = dg::diagnose(column_problem(
          1, 0.0, [&](double v) { return c.map(v, a); }, [](double v) { return v; }, false));
      for (const dg::Finding& f : r.findings) {
        if (f.physics != "nonlinear_gain" || f.channels.size() != 1) continue;
        seen += f.summary + "; ";
        EXPECT_EQ(f.channels[0].output, 0u) << c.name << " a " << a << ": " << f.summary;
        if (f.parameters.at(c.absent) == 0.0) {
          alone = true;
          EXPECT_NE(f.parameters.at(c.term), 0.0) << c.name << " a " << a << ": " << f.summary;
          EXPECT_EQ(f.params, 2) << c.name << " a " << a << ": " << f.summary;
        }
      }
    }
    EXPECT_TRUE(alone) << c.name << ": never named by its own term alone up to a = 0.3; " << seen;
  }
}

// The rule itself, at the level the static map uses (1 %, one term on one
// channel: the fit part's limit alone is 6.63, the pooled one 9.21).
TEST(DiagnosisNonlinearGain, TheBendsNestedTestPoolsTheHeldOutPart) {
  const double level = dg::Settings{}.beyond_noise_level;
  // Under the fit part's limit, confirmed on the held-out part: there.
  EXPECT_TRUE(dg::beyond_nested(5.0, 2.5, 1, level));
  // Past the fit part's limit but contradicted on the held-out part: not.
  EXPECT_FALSE(dg::beyond_nested(8.0, -0.5, 1, level));
  // Pooled just under the limit: not; just over it: there.
  const double limit = mpm::chi_square_quantile_upper(level, 2);
  EXPECT_FALSE(dg::beyond_nested(limit - 1.0 - 0.01, 1.0, 1, level));
  EXPECT_TRUE(dg::beyond_nested(limit - 1.0 + 0.01, 1.0, 1, level));
  // More terms, more degrees of freedom.
  EXPECT_FALSE(dg::beyond_nested(limit, 1.0, 2, level));
}

// A soft saturation v / (1 + a |v|) growing from nothing: at some strength
// it is named while its fit part alone is under that part's own limit
// (nonlinear_lr below the chi-square quantile of its terms), admitted by
// the held-out confirmation (nonlinear_holdout_z > 0): the fit part alone
// would have left it a gain.
TEST(DiagnosisNonlinearGain, ABendTheHeldOutPartConfirmsIsNamedUnderTheFitPartsLimit) {
  const double level = dg::Settings{}.beyond_noise_level;
  std::string seen;
  bool pooled = false;
  for (unsigned seed : {1u, 2u, 3u})
    for (double a = 0.005; a < 0.3 && !pooled; a *= 1.15) {
      const dg::Result r = dg::diagnose(column_problem(
          seed, 0.0, [&](double v) { return v / (1.0 + a * std::abs(v)); }, [](double v) { return v; }, false));
      for (const dg::Finding& f : r.findings) {
        if (f.physics != "nonlinear_gain") continue;
        const double lr = f.parameters.at("nonlinear_lr");
        const double z = f.parameters.at("nonlinear_holdout_z");
        seen += "seed " + std::to_string(seed) + " a " + std::to_string(a) + ": LR " + std::to_string(lr) + " z " +
                std::to_string(z) + "; ";
        EXPECT_GT(z, 0.0) << f.summary;
        // (1 + terms) parameters per channel: terms x channels beyond the gains.
        const int df = f.params - static_cast<int>(f.channels.size());
        if (lr < mpm::chi_square_quantile_upper(level, df)) pooled = true;
      }
    }
  EXPECT_TRUE(pooled) << "every bend named was past the fit part's limit alone: " << seen;
}

// Plain gains on one channel, over many seeds, stay gains: the held-out
// part must confirm a bend, so a fit-part wiggle of a linear change is not
// called a static map.
TEST(DiagnosisNonlinearGain, APlainGainIsRarelyCalledAStaticMap) {
  int gains = 0, maps = 0;
  for (unsigned seed = 1; seed <= 30; ++seed) {
    const double factor = seed % 2 ? 1.3 : 0.75;
    const dg::Result r = dg::diagnose(column_problem(
        seed, 0.0, [&](double v) { return factor * v; }, [](double v) { return v; }, false));
    for (const dg::Finding& f : r.findings) {
      gains += f.physics == "gain";
      maps += f.physics == "nonlinear_gain";
    }
  }
  // Three forms tried at 1 % each: a few percent at most.
  EXPECT_LE(maps, 1);
  EXPECT_GE(gains, 29);
}

}  // namespace
