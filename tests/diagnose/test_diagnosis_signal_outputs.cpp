// A recorded signal accepted on one output is established: on the other
// outputs its candidates are tested as a family of their own (gatekeeping),
// not at the round's family-wise limit. Planted: one input, two outputs, a
// recorded signal z that drives y1 strongly and y2 weakly, white noise. At
// some weak gain on y2, a record where z drives y2 alone reports nothing
// (under the round's limit), while the record where z also drives y1 names
// z on both outputs.
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "core/diagnosis.hpp"

namespace {

using mpm::DiscreteTf;
namespace dg = mpm::diagnosis;

const DiscreteTf kChannel{{0.2}, {1.0, -0.8}, 1};  // u -> y1 and u -> y2, both modelled right

// z: steps of +-1 held 60 samples; the residual of y_j is g_j (0.3 q^-2 /
// (1 - 0.7 q^-1)) z plus white noise of standard deviation 0.1.
dg::Problem record(unsigned seed, double g1, double g2) {
  const Eigen::Index n = 4000;
  std::mt19937 rng(seed);
  std::normal_distribution<double> step(0.0, 1.0), noise(0.0, 0.1);
  Eigen::VectorXd u(n), z(n);
  double hu = 0.0, hz = 0.0;
  for (Eigen::Index k = 0; k < n; ++k) {
    if (k % 40 == 0) hu = step(rng);
    if (k % 60 == 0) hz = step(rng) > 0.0 ? 1.0 : -1.0;
    u(k) = hu;
    z(k) = hz;
  }
  dg::Problem p;
  p.inputs = {"u"};
  p.outputs = {"y1", "y2"};
  p.du = Eigen::MatrixXd(n, 1);
  p.du.col(0) = u;
  p.u_abs = p.du;
  p.residual = Eigen::MatrixXd(n, 2);
  double s = 0.0;
  for (Eigen::Index k = 0; k < n; ++k) {
    if (k >= 2) s = 0.7 * s + 0.3 * z(k - 2);
    p.residual(k, 0) = g1 * s + noise(rng);
    p.residual(k, 1) = g2 * s + noise(rng);
  }
  p.nominal = {kChannel, kChannel};
  p.noise = {DiscreteTf{{1.0}, {1.0}, 0}, DiscreteTf{{1.0}, {1.0}, 0}};
  p.noise_variance = {0.01, 0.01};
  p.extra_names = {"feed"};
  p.extra = Eigen::MatrixXd(n, 1);
  p.extra.col(0) = z;
  p.monitor_flag = {false, false};
  p.monitor_located = {{}, {}};
  return p;
}

bool names_feed_on(const dg::Result& r, std::size_t output) {
  for (const dg::Finding& f : r.findings)
    if (f.physics == "unmodeled_input" && f.signal == std::optional<std::string>("feed"))
      for (const auto& c : f.channels)
        if (c.output == output) return true;
  return false;
}

TEST(DiagnosisSignalOutputs, ASignalFoundOnOneOutputIsTestedOnTheOthersAsItsOwnFamily) {
  const dg::Settings settings;
  int between = 0;
  for (unsigned seed : {1u, 2u, 3u}) {
    for (double g2 = 0.002; g2 < 0.02; g2 += 0.001) {
      const dg::Result alone = dg::diagnose(record(seed, 0.0, g2), settings);
      if (names_feed_on(alone, 1)) break;  // past the round's limit on its own
      const dg::Result both = dg::diagnose(record(seed, 1.0, g2), settings);
      ASSERT_TRUE(names_feed_on(both, 0)) << "seed " << seed;
      EXPECT_FALSE(names_feed_on(alone, 0)) << "z does not drive y1 there";
      if (names_feed_on(both, 1)) ++between;
    }
  }
  EXPECT_GT(between, 0) << "at no weak gain was z named on y2 once established on y1";
}

}  // namespace
