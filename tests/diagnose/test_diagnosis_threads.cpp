// The diagnosis's search is the same whatever runs it: its hypothesis
// generators on one thread or several (candidates appended in call order),
// and candidates that keep only their numbers during the search, the chosen
// one rebuilt with its columns. A two-input loop with a gain mismatch on one
// channel and a recorded signal the model leaves out, so that a process
// finding and a signal finding are both chosen and rebuilt.
#include <cstddef>
#include <random>

#include <gtest/gtest.h>

#include "core/diagnosis.hpp"
#include "support/diagnosis_problem.hpp"

namespace {

using mpm::DiscreteTf;
namespace dg = mpm::diagnosis;

dg::Problem two_input_loop(unsigned seed) {
  const Eigen::Index n = 5000;
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 0.05), dither(0.0, 0.5);
  Eigen::MatrixXd u = Eigen::MatrixXd::Zero(n, 2);
  Eigen::VectorXd y = Eigen::VectorXd::Zero(n), gu = y, z = y;
  for (Eigen::Index k = 0; k < n; ++k) z(k) = (k / 200) % 3 == 1 ? 1.0 : 0.0;
  double x1 = 0.0, x2 = 0.0, m1 = 0.0, m2 = 0.0, xz = 0.0, integ = 0.0;
  for (Eigen::Index k = 0; k < n; ++k) {
    y(k) = x1 + x2 + xz + noise(rng);
    gu(k) = m1 + m2;
    integ += y(k);
    u(k, 0) = -0.5 * y(k) - 0.03 * integ + dither(rng);
    u(k, 1) = dither(rng);
    x1 = 0.9 * x1 + 0.1 * 1.4 * u(k, 0);  // the plant's gain is 1.4 x the model's
    m1 = 0.9 * m1 + 0.1 * u(k, 0);
    x2 = 0.8 * x2 + 0.2 * -0.6 * u(k, 1);
    m2 = 0.8 * m2 + 0.2 * -0.6 * u(k, 1);
    xz = 0.7 * xz + 0.3 * 0.8 * z(k);     // the recorded signal the model lacks
  }
  dg::Problem p = mpm::test::one_output_problem(
      {"u1", "u2"}, u, y - gu, {DiscreteTf{{0.1}, {1.0, -0.9}, 1}, DiscreteTf{{-0.12}, {1.0, -0.8}, 1}},
      DiscreteTf{{1.0}, {1.0}, 0}, 0.05 * 0.05);
  p.extra_names = {"z"};
  p.extra = z;
  return p;
}

TEST(DiagnosisThreads, SameFindingsOnOneThreadOrSeveral) {
  const dg::Problem p = two_input_loop(5);
  dg::Settings one, several;
  several.threads = 3;
  const dg::Result a = dg::diagnose(p, one), b = dg::diagnose(p, several);
  ASSERT_GE(a.findings.size(), 2u);  // the gain and the signal at least: both rebuilt after the search
  ASSERT_EQ(a.findings.size(), b.findings.size());
  bool gain = false, signal = false;
  for (std::size_t f = 0; f < a.findings.size(); ++f) {
    const dg::Finding &x = a.findings[f], &y = b.findings[f];
    gain = gain || (x.physics == "gain" && x.channels[0].input == std::size_t{0});
    signal = signal || x.signal.has_value();
    EXPECT_EQ(x.physics, y.physics);
    EXPECT_EQ(x.summary, y.summary);
    EXPECT_EQ(x.lr, y.lr);  // exactly: the same fits in the same order
    EXPECT_EQ(x.fit.residual_variance_after, y.fit.residual_variance_after);
    EXPECT_EQ(x.raw.holdout_variance_after, y.raw.holdout_variance_after);
    EXPECT_EQ(x.parameters, y.parameters);
    EXPECT_EQ(x.alternatives, y.alternatives);
    ASSERT_EQ(x.fitted.has_value(), y.fitted.has_value());
    if (x.fitted) {
      EXPECT_EQ(x.fitted->num, y.fitted->num);
      EXPECT_EQ(x.fitted->den, y.fitted->den);
    }
  }
  EXPECT_TRUE(gain) << "the planted gain of u1 was not found";
  EXPECT_TRUE(signal) << "the recorded signal z was not found";
}

}  // namespace
