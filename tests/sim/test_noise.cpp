// Coloured noise d = N a: variance, AR(1) correlation, determinism per seed;
// setpoint profiles.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "sim/noise.hpp"
#include "sim/setpoints.hpp"
#include "sim/sim_test_support.hpp"

namespace mpm::sim {
namespace {

std::vector<std::vector<double>> draw(NoiseSource& src, std::size_t outputs, std::size_t n) {
  std::vector<std::vector<double>> d(outputs, std::vector<double>(n));
  std::vector<double> row(outputs);
  for (std::size_t k = 0; k < n; ++k) {
    src.draw(row.data());
    for (std::size_t j = 0; j < outputs; ++j) d[j][k] = row[j];
  }
  return d;
}

double variance(const std::vector<double>& x) {
  double m = 0.0, s = 0.0;
  for (double v : x) m += v;
  m /= static_cast<double>(x.size());
  for (double v : x) s += (v - m) * (v - m);
  return s / static_cast<double>(x.size());
}

double lag1_correlation(const std::vector<double>& x) {
  double num = 0.0, den = 0.0;
  for (std::size_t k = 1; k < x.size(); ++k) num += x[k] * x[k - 1];
  for (double v : x) den += v * v;
  return num / den;
}

TEST(Noise, Ar1NoiseHasTheRightVarianceAndCorrelation) {
  const PlantModel m = testing::example_plant("wood-berry.yaml");  // N = 1/(1-0.8q^-1), 1/(1-0.9q^-1)
  NoiseSource src(noise_channels(m, 1.0), 42);
  const std::size_t n = 400000;
  const auto d = draw(src, 2, n);
  const double poles[2] = {0.8, 0.9};
  for (std::size_t j = 0; j < 2; ++j) {
    const double expected = 1.0 / (1.0 - poles[j] * poles[j]);
    // Standard error of the variance of an AR(1): ~ sqrt(2 (1+p^2)/(1-p^2) / n) relative.
    EXPECT_NEAR(variance(d[j]) / expected, 1.0, 0.03) << "output " << j;
    EXPECT_NEAR(lag1_correlation(d[j]), poles[j], 0.01) << "output " << j;
  }
}

TEST(Noise, VarianceScalesAndWhiteNoiseIsUncorrelated) {
  std::vector<NoiseChannel> ch(1);
  ch[0].variance = 4.0;  // white
  NoiseSource src(ch, 9, 0.5);  // scale 0.5 on a: variance 1
  const auto d = draw(src, 1, 200000);
  EXPECT_NEAR(variance(d[0]), 1.0, 0.02);
  EXPECT_NEAR(lag1_correlation(d[0]), 0.0, 0.01);
  NoiseSource off(ch, 9, 0.0);
  const auto z = draw(off, 1, 100);
  for (double v : z[0]) EXPECT_EQ(v, 0.0);
}

TEST(Noise, SameSeedSameSequenceDifferentSeedDifferent) {
  const PlantModel m = testing::example_plant("wood-berry.yaml");
  NoiseSource a(noise_channels(m, 1.0), 5), b(noise_channels(m, 1.0), 5), c(noise_channels(m, 1.0), 6);
  const auto da = draw(a, 2, 1000), db = draw(b, 2, 1000), dc = draw(c, 2, 1000);
  EXPECT_EQ(da, db);
  EXPECT_NE(da, dc);
}

TEST(Noise, OutputsWithoutANoiseModelGetTheDefault) {
  PlantModel m = testing::example_plant("wood-berry.yaml");
  m.noise[1].reset();
  const auto ch = noise_channels(m, 0.25);
  EXPECT_EQ(ch[1].filter.den, std::vector<double>{1.0});
  EXPECT_EQ(ch[1].variance, 0.25);
  EXPECT_EQ(ch[0].variance, 1.0);
}

TEST(Setpoints, ScheduledStepsSineInAZoneAndRandomSteps) {
  SetpointSpec step;
  step.steps = {{200, 15.0}};
  SetpointSpec zone;
  zone.sine_amplitude = 12.0;
  zone.sine_frequency = 0.05;
  zone.zone_lower = -9.0;
  zone.zone_upper = 9.0;
  SetpointSpec random;
  random.initial = 1.0;
  random.random_amplitude = 0.5;
  random.random_period_min = 50;
  random.random_period_max = 100;
  SetpointGenerator gen({step, zone, random}, 2.0, 3);
  double r[3];
  int changes = 0;
  double previous = 1.0, lo = 1e9, hi = -1e9;
  for (long k = -10; k < 3000; ++k) {
    gen.at(k, r);
    EXPECT_EQ(r[0], k < 200 ? 0.0 : 15.0);
    EXPECT_NEAR(r[1], std::clamp(12.0 * std::sin(0.05 * 2.0 * static_cast<double>(k)), -9.0, 9.0), 1e-12);
    if (r[2] != previous) ++changes;
    previous = r[2];
    lo = std::min(lo, r[2]);
    hi = std::max(hi, r[2]);
  }
  EXPECT_GE(changes, 3000 / 100 - 1);
  EXPECT_LE(changes, 3000 / 50 + 1);
  EXPECT_GE(lo, 0.5);
  EXPECT_LE(hi, 1.5);
  EXPECT_LT(lo, 0.8);  // the draws spread over the band
  EXPECT_GT(hi, 1.2);
}

}  // namespace
}  // namespace mpm::sim
