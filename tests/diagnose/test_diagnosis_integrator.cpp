// The diagnosis library on an integrating plant that the model took for a
// self-regulating one. Under feedback the controller holds the output still
// at the plant's own balance input, which is not the model's operating
// point: the integrator hypothesis must fit that offset, or the offset
// integrates into a drift no gain can fit and the physics is misnamed.
#include <cstddef>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "core/diagnosis.hpp"
#include "support/diagnosis_problem.hpp"

namespace {

using mpm::DiscreteTf;
namespace dg = mpm::diagnosis;

// Plant: y(k+1) = y(k) + 0.035 (u(k) - u_b) + disturbance; model:
// 0.05 q^-1 / (1 - 0.975 q^-1) (DC gain 2, time constant 40 samples, the
// same slope at first). A PI controller with dither regulates y to 0.
dg::Problem integrating_loop(unsigned seed, double balance) {
  const std::size_t n = 6000;
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.02), dither(0.0, 0.3);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n));
  Eigen::VectorXd y = u, gu = u;
  double x = 0.0, xm = 0.0, integ = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    y(i) = x + noise(rng);
    gu(i) = xm;
    integ += y(i);
    u(i) = -2.0 * y(i) - 0.02 * integ + dither(rng);
    x += 0.035 * (u(i) - balance);
    xm = 0.975 * xm + 0.05 * u(i);
  }
  return mpm::test::one_output_problem({"u"}, u, y - gu, {DiscreteTf{{0.05}, {1.0, -0.975}, 1}},
                                      DiscreteTf{{1.0}, {1.0}, 0}, 0.02 * 0.02);
}

TEST(DiagnosisIntegrator, IntegratorAwayFromTheModelsOperatingPoint) {
  for (unsigned seed : {1u, 2u}) {
    const dg::Result r = dg::diagnose(integrating_loop(seed, 0.8));
    ASSERT_FALSE(r.findings.empty()) << "seed " << seed;
    const dg::Finding& f = r.findings.front();
    EXPECT_EQ(f.physics, "integrator") << "seed " << seed << ": " << f.summary;
    // 0.035 per sample against the model's 0.05 (1 - 0.975) / (1 - 0.975).
    EXPECT_NEAR(f.parameters.at("integrator_gain_per_sample"), 0.035, 0.005) << "seed " << seed << ": " << f.summary;
    EXPECT_NEAR(f.parameters.at("balance_input_offset"), 0.8, 0.1) << "seed " << seed << ": " << f.summary;
    EXPECT_LT(f.fit.holdout_variance_after, f.fit.holdout_variance_before) << "seed " << seed;
  }
}

}  // namespace
