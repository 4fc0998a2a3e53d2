// The pooled evidence of a candidate (passes() in diagnosis_score.cpp): the
// fit part's sqrt(lr) and the held-out z weighted by their shares of the
// samples. Its null tail against a Monte Carlo of the statistic it claims to
// be (chi-square fit part, standard normal held-out part, independent) and
// against its limits; and that it decides a candidate as the level says.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "core/chi_square.hpp"
#include "core/diagnosis_context.hpp"

namespace {

namespace dg = mpm::diagnosis;

// P(sqrt(1 - h) sqrt(X) + sqrt(h) Z >= t) by simulation, X ~ chi-square(k).
double simulated_tail(double t, int k, double h, int draws, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  int above = 0;
  for (int d = 0; d < draws; ++d) {
    double x = 0.0;
    for (int i = 0; i < k; ++i) {
      const double g = normal(rng);
      x += g * g;
    }
    above += std::sqrt(1.0 - h) * std::sqrt(x) + std::sqrt(h) * normal(rng) >= t;
  }
  return static_cast<double>(above) / draws;
}

TEST(PooledEvidence, NullTailMatchesTheStatisticSimulated) {
  constexpr int kDraws = 400000;
  for (const int k : {1, 3}) {
    for (const double t : {1.0, 2.5, 3.5}) {
      const double p = dg::pooled_evidence_survival(t, k, 0.3);
      const double sim = simulated_tail(t, k, 0.3, kDraws, 11u + static_cast<unsigned>(k));
      const double se = std::sqrt(p * (1.0 - p) / kDraws);
      EXPECT_NEAR(sim, p, 5.0 * se + 1e-6) << "k " << k << " t " << t;
    }
  }
}

TEST(PooledEvidence, LimitsAndShape) {
  // Without a held-out part it is the fit part's own chi-square tail.
  for (const int k : {1, 2, 4})
    for (const double t : {1.0, 3.0, 4.5})
      EXPECT_NEAR(dg::pooled_evidence_survival(t, k, 1e-8), mpm::chi_square_survival(t * t, k),
                  1e-4 * mpm::chi_square_survival(t * t, k))
          << k << " " << t;
  // Far below any evidence it is certain; it falls as the statistic grows.
  EXPECT_NEAR(dg::pooled_evidence_survival(-20.0, 2, 0.3), 1.0, 1e-9);
  double previous = 1.0;
  for (double t = 0.0; t < 8.0; t += 0.5) {
    const double p = dg::pooled_evidence_survival(t, 2, 0.3);
    EXPECT_LT(p, previous) << t;
    previous = p;
  }
  EXPECT_GT(previous, 0.0);
  EXPECT_TRUE(std::isnan(dg::pooled_evidence_survival(1.0, 0, 0.3)));
  EXPECT_TRUE(std::isnan(dg::pooled_evidence_survival(1.0, 1, 0.0)));
  EXPECT_TRUE(std::isnan(dg::pooled_evidence_survival(1.0, 1, 1.0)));
}

TEST(PooledEvidence, ChiSquareDensity) {
  EXPECT_NEAR(mpm::chi_square_density(1.0, 1.0), std::exp(-0.5) / std::sqrt(2.0 * M_PI), 1e-14);
  EXPECT_NEAR(mpm::chi_square_density(3.0, 2.0), 0.5 * std::exp(-1.5), 1e-14);
  EXPECT_EQ(mpm::chi_square_density(-1.0, 3.0), 0.0);
  EXPECT_TRUE(std::isnan(mpm::chi_square_density(1.0, 0.0)));
}

// A candidate whose held-out part contradicts its fit (z < 0) carries less
// evidence than its fit part alone; one it confirms, more. The same fit LR
// with a held-out z that agrees in size passes where lr + z^2 on two
// degrees of freedom would not have (the fit LR 18, z 2.5 of a 30 % share).
TEST(PooledEvidence, HeldOutPartAddsOrSubtracts) {
  dg::Candidate c;
  c.params = 1;
  c.lr = 18.0;
  c.hold_share = 0.3;
  c.z_hold = -1.0;
  const double against = dg::pooled_evidence_p(c);
  c.z_hold = 0.0;
  const double silent = dg::pooled_evidence_p(c);
  c.z_hold = 2.5;
  const double confirmed = dg::pooled_evidence_p(c);
  EXPECT_GT(against, silent);
  EXPECT_GT(silent, confirmed);
  const double level = 3e-6;
  EXPECT_LT(confirmed, level);
  EXPECT_GT(mpm::chi_square_survival(18.0 + 2.5 * 2.5, 2), level);
  c.hold_share = 0.0;  // no held-out part: no pooled evidence
  EXPECT_EQ(dg::pooled_evidence_p(c), 1.0);
}

}  // namespace
