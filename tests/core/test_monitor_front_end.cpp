// The front end every monitor shares (core/monitor_front_end.hpp): the u0
// rule, sim_ columns, held inputs, settling, the monitor built from a plant,
// and the alarm edges. Planted truth: a 2x2 first-order plant written out
// here, its residuals computed by hand.
#include "core/monitor_front_end.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "support/alloc_counter.hpp"
#include "core/chi_square.hpp"
#include "core/noise_filter.hpp"

namespace mpm {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// y1 = 0.5 q^-1 / (1 - 0.9 q^-1) u1 (+ nothing from u2), y2 = 0.2 q^-2 / (1 - 0.5 q^-1) u2,
// AR(1) noise models with variance 1.
PlantModel plant(bool with_operating_point) {
  PlantModel p;
  p.name = "two-by-two";
  p.sample_time = 2.0;
  p.inputs = {"u1", "u2"};
  p.outputs = {"y1", "y2"};
  p.channels.push_back({0, 0, DiscreteTf{{0.0, 0.5}, {1.0, -0.9}, 0}, false, std::nullopt});
  p.channels.push_back({1, 1, DiscreteTf{{0.0, 0.2}, {1.0, -0.5}, 1}, false, std::nullopt});
  p.noise.push_back(NoiseModel{DiscreteTf{{1.0}, {1.0, -0.8}, 0}, 1.0});
  p.noise.push_back(NoiseModel{DiscreteTf{{1.0}, {1.0, -0.7}, 0}, 1.0});
  if (with_operating_point) p.operating_point = OperatingPoint{{3.0, -1.0}, {0.0, 0.0}};
  return p;
}

TEST(InputOrigin, IsTheOperatingPointElseTheFirstCompleteSample) {
  InputOrigin given(plant(true));
  EXPECT_TRUE(given.known());
  EXPECT_EQ(given.u0(), (std::vector<double>{3.0, -1.0}));
  const double later[] = {7.0, 8.0};
  EXPECT_TRUE(given.offer(later));
  EXPECT_EQ(given.u0(), (std::vector<double>{3.0, -1.0})) << "the plant file's operating point wins";

  InputOrigin found(plant(false));
  EXPECT_FALSE(found.known());
  EXPECT_EQ(found.u0(), (std::vector<double>{0.0, 0.0}));
  const double partial[] = {5.0, kNaN}, complete[] = {6.0, 2.0}, next[] = {9.0, 9.0};
  EXPECT_FALSE(found.offer(partial));
  EXPECT_TRUE(found.offer(complete));
  EXPECT_TRUE(found.offer(next));
  EXPECT_EQ(found.u0(), (std::vector<double>{6.0, 2.0}));

  Eigen::MatrixXd u(3, 2);
  u << kNaN, 1.0, 4.0, 5.0, 6.0, 7.0;
  EXPECT_EQ(input_origin(plant(false), u), (std::vector<double>{4.0, 5.0}));
  EXPECT_EQ(input_origin(plant(true), u), (std::vector<double>{3.0, -1.0}));
}

TEST(HeldDeviations, HoldTheLastGoodInputAndStartAtTheOrigin) {
  Eigen::MatrixXd u(4, 2);
  u << kNaN, 2.0, 5.0, kNaN, kNaN, 4.0, 7.0, 1.0;
  const Eigen::MatrixXd du = held_deviations(u, {1.0, 2.0});
  Eigen::MatrixXd expected(4, 2);
  expected << 0.0, 0.0, 4.0, 0.0, 4.0, 2.0, 6.0, -1.0;
  EXPECT_EQ(du, expected);
}

TEST(SettleLength, TheUsersWordThenSimulationThenThePlant) {
  const PlantModel p = plant(false);
  EXPECT_EQ(settle_length(p, 17, 5), 17u);
  EXPECT_EQ(settle_length(p, 17, 5, true), 17u);
  EXPECT_EQ(settle_length(p, -1, 5000, true), 0u);
  const std::size_t automatic = settle_length(p, -1, 5000);
  EXPECT_EQ(automatic, settling_samples(p, 0.01, 5000));
  // 0.9^k < 0.01 from k = 44, plus the longest delay.
  EXPECT_GT(automatic, 40u);
  EXPECT_LT(automatic, 60u);
  EXPECT_EQ(settle_length(p, -1, 10), 10u);
  EXPECT_EQ(record_settle_cap(3000), 300u);
}

// The residual by hand: y - G (u - u0), each filter a difference equation.
struct HandModel {
  std::vector<double> u0;
  double x1 = 0.0, x2 = 0.0, du2_prev = 0.0;
  void residual(const double* u, const double* y, double* r) {
    const double du1 = u[0] - u0[0], du2 = u[1] - u0[1];
    const double g1 = x1, g2 = x2;  // outputs at k, from inputs up to k-1 (k-2 for the delayed channel)
    x1 = 0.9 * x1 + 0.5 * du1;
    x2 = 0.5 * x2 + 0.2 * du2_prev;
    du2_prev = du2;
    r[0] = y[0] - g1;
    r[1] = y[1] - g2;
  }
};

TEST(ResidualFrontEnd, LiveWaitsForTheOriginThenSettlesThenIsReady) {
  const PlantModel p = plant(false);
  ResidualFrontEnd live(p, 3);
  EXPECT_EQ(live.settle(), 3);
  std::mt19937_64 rng(3);
  std::normal_distribution<double> normal(0.0, 1.0);
  double r[2], by_hand[2];
  const double partial[] = {kNaN, 1.0}, y0[] = {0.0, 0.0};
  EXPECT_EQ(live.step(partial, y0, nullptr, r), ResidualFrontEnd::Stage::kNoOrigin);
  EXPECT_FALSE(live.has_origin());

  HandModel hand;
  std::vector<ResidualFrontEnd::Stage> stages;
  for (int k = 0; k < 200; ++k) {
    const double u[] = {10.0 + normal(rng), -4.0 + normal(rng)}, y[] = {normal(rng), normal(rng)};
    if (k == 0) hand.u0 = {u[0], u[1]};
    stages.push_back(live.step(u, y, nullptr, r));
    hand.residual(u, y, by_hand);
    EXPECT_NEAR(r[0], by_hand[0], 1e-12) << k;
    EXPECT_NEAR(r[1], by_hand[1], 1e-12) << k;
  }
  EXPECT_TRUE(live.has_origin());
  for (int k = 0; k < 3; ++k) EXPECT_EQ(stages[static_cast<std::size_t>(k)], ResidualFrontEnd::Stage::kSettling);
  EXPECT_EQ(stages[3], ResidualFrontEnd::Stage::kReady);
  live.resettle();
  const double u[] = {10.0, -4.0}, y[] = {0.0, 0.0};
  EXPECT_EQ(live.step(u, y, nullptr, r), ResidualFrontEnd::Stage::kSettling);
}

TEST(ResidualFrontEnd, LiveAndOfflineGiveTheSameResidualsBitForBit) {
  for (const bool op : {false, true}) {
    const PlantModel p = plant(op);
    std::mt19937_64 rng(5);
    std::normal_distribution<double> normal(0.0, 1.0);
    Eigen::MatrixXd u(500, 2), y(500, 2);
    for (Eigen::Index k = 0; k < 500; ++k) {
      u(k, 0) = k % 37 == 5 ? kNaN : 2.0 + normal(rng);  // gaps: the model holds the last input
      u(k, 1) = normal(rng);
      y(k, 0) = normal(rng);
      y(k, 1) = normal(rng);
    }
    ResidualFrontEnd live(p, 20);
    ResidualFrontEnd offline(p, input_origin(p, u), 20);
    for (Eigen::Index k = 0; k < 500; ++k) {
      const Eigen::RowVector2d uk = u.row(k), yk = y.row(k);
      double a[2], b[2];
      const auto sa = live.step(uk.data(), yk.data(), nullptr, a);
      const auto sb = offline.step(uk.data(), yk.data(), nullptr, b);
      ASSERT_EQ(sa, sb) << k;
      for (int j = 0; j < 2; ++j) {
        ASSERT_EQ(std::isnan(a[j]), std::isnan(b[j])) << k;
        if (!std::isnan(a[j])) {
          ASSERT_EQ(a[j], b[j]) << k;
        }
      }
      if (k % 37 == 5) {
        EXPECT_TRUE(std::isnan(a[0])) << "a missing input leaves a missing residual";
      }
    }
  }
}

TEST(ResidualFrontEnd, TheControllersPredictionReplacesTheModelWhereItIsUsed) {
  const PlantModel p = plant(true);
  ResidualFrontEnd both(p, 0);                                   // live: every output
  ResidualFrontEnd first_only(p, {3.0, -1.0}, 0, {true, false});  // offline: a sim_ column for y1 only
  ResidualFrontEnd model(p, {3.0, -1.0}, 0);
  const double u[] = {4.0, 0.0}, y[] = {1.5, 2.5}, sim[] = {1.0, 2.0};
  double a[2], b[2], m[2];
  for (int k = 0; k < 5; ++k) {
    both.step(u, y, sim, a);
    first_only.step(u, y, sim, b);
    model.step(u, y, nullptr, m);
    EXPECT_EQ(a[0], 0.5);
    EXPECT_EQ(a[1], 0.5);
    EXPECT_EQ(b[0], 0.5);
    EXPECT_EQ(b[1], m[1]) << "y2 has no sim_ column: the model's residual";
  }
  EXPECT_NE(m[0], 0.5);
}

TEST(ResidualFrontEnd, StepAllocatesNothing) {
  const PlantModel p = plant(false);
  ResidualFrontEnd live(p, 2);
  const double u[] = {1.0, 2.0}, y[] = {0.0, 0.0};
  double r[2];
  test::AllocationScope scope;
  for (int k = 0; k < 10; ++k) live.step(u, y, nullptr, r);  // the origin is found here: no allocation either
  EXPECT_EQ(scope.count(), 0);
}

TEST(MonitorBlueprint, BuildsWhatTheHandWrittenConstructorDoes) {
  const PlantModel p = plant(true);
  MonitorSettings s;
  s.ar_order = 4;
  s.input_order = 4;
  const MonitorBlueprint blueprint(p, s);
  EXPECT_EQ(blueprint.settings().detector.sample_time, 2.0) << "the plant's sample time";
  GrangerMonitor built = blueprint.build();
  GrangerMonitor by_hand(2, 2, for_plant(s, p), noise_ar(p, 4), reference_variances(p), channel_models(p));
  std::mt19937_64 rng(9);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int k = 0; k < 400; ++k) {
    const double u[] = {normal(rng), normal(rng)}, d[] = {normal(rng), normal(rng)};
    built.update(u, d);
    by_hand.update(u, d);
  }
  for (std::size_t j = 0; j < 2; ++j)
    for (std::size_t i = 0; i < 2; ++i) {
      EXPECT_EQ(built.channel(j, i).lr_conditional, by_hand.channel(j, i).lr_conditional);
      EXPECT_EQ(built.channel(j, i).gamma, by_hand.channel(j, i).gamma);
      EXPECT_TRUE(std::isfinite(built.channel(j, i).gamma)) << "noise models given: gamma known";
    }
  EXPECT_EQ(noise_ar(p, 4)[0], inverse_noise_ar_coefficients(p.noise[0]->tf, 4));
  EXPECT_GT(reference_variances(p)[0], 1.0);  // 1 / (1 - 0.8^2)
  EXPECT_TRUE(channel_models(p)[0 * 2 + 0].has_value());
  EXPECT_FALSE(channel_models(p)[0 * 2 + 1].has_value());
}

// A residual that u1 drives (planted): the detector raises y1 and names u1;
// AlarmEdges reports that raise once, and alarm_facts what it was.
TEST(AlarmEdges, ReportEachRaiseOnceWithItsFacts) {
  const PlantModel p = plant(false);
  MonitorSettings s;
  s.ar_order = 2;
  s.input_order = 2;
  const MonitorBlueprint blueprint(p, s, true);
  GrangerMonitor m = blueprint.build();
  AlarmEdges edges(2, 2);
  std::mt19937_64 rng(11);
  std::normal_distribution<double> normal(0.0, 1.0);
  double u_prev = 0.0;
  int raises = 0;
  std::size_t raised_output = 9, raised_input = 9;
  AlarmFacts facts;
  for (int k = 0; k < 6000 && raises == 0; ++k) {
    const double u[] = {normal(rng), normal(rng)};
    const double gain = k < 1000 ? 0.0 : 0.5;  // the mismatch appears at sample 1000
    const double d[] = {normal(rng) + gain * u_prev, normal(rng)};
    u_prev = u[0];
    m.update(u, d);
    edges.scan(m, [&](std::size_t j, std::size_t i, bool raised) {
      ASSERT_TRUE(raised);
      ++raises;
      raised_output = j;
      raised_input = i;
      facts = alarm_facts(m, j, i);
    });
    edges.scan(m, [&](std::size_t, std::size_t, bool) { ADD_FAILURE() << "an edge reported twice"; });
  }
  ASSERT_EQ(raises, 1);
  EXPECT_EQ(raised_output, 0u);
  EXPECT_EQ(raised_input, 0u);
  EXPECT_TRUE(edges.raised(0, 0));
  EXPECT_TRUE(facts.raised);
  EXPECT_GT(facts.statistic, facts.threshold);
  EXPECT_EQ(facts.statistic, m.loop(0).score);
  EXPECT_GT(facts.window, 0.0);
  EXPECT_LT(facts.p_value, 1e-3);
  edges.lower(0, 0);
  int again = 0;
  edges.scan(m, [&](std::size_t, std::size_t, bool raised) { again += raised ? 1 : 0; });
  EXPECT_EQ(again, 1) << "a lowered flag that is still raised is reported again";
}


// The record's verdict shared over its tests: a residual that u1 drives
// weakly, at the first planted gain whose conditional LR on y1 <- u1 lands
// between the per-test limit and the family-wise one (the whole record's
// channels and loops at false_alarm). Per test it is a mismatch, family-wise
// not; a strong gain is one either way.
TEST(RecordVerdict, AFamilyWiseLevelFlagsOnlyPastItsStricterLimit) {
  const PlantModel p = plant(false);
  MonitorSettings s;
  s.ar_order = 2;
  s.input_order = 2;
  s.forgetting = 1.0;
  const MonitorBlueprint blueprint(p, s, true);
  const auto record = [&](double gain) {
    GrangerMonitor m = blueprint.build();
    std::mt19937_64 rng(21);
    std::normal_distribution<double> normal(0.0, 1.0);
    double u_prev = 0.0;
    for (int k = 0; k < 3000; ++k) {
      const double u[] = {normal(rng), normal(rng)};
      const double d[] = {normal(rng) + gain * u_prev, normal(rng)};
      u_prev = u[0];
      m.update(u, d);
    }
    return m;
  };
  const double per_test = chi_square_quantile_upper(s.false_alarm, 2);
  double family_wise = 0.0;
  bool between = false;
  for (double gain = 0.02; gain < 0.2 && !between; gain += 0.002) {
    const GrangerMonitor m = record(gain);
    EXPECT_EQ(record_test_count(m), 6.0) << "2 outputs x (2 channels + the loop)";
    family_wise = chi_square_quantile_upper(s.false_alarm / record_test_count(m), 2);
    const double joint_family_wise = chi_square_quantile_upper(s.false_alarm / record_test_count(m), 4);
    const double lr = m.channel(0, 0).lr_conditional;
    if (lr <= per_test || lr >= family_wise || m.loop(0).lr_joint >= joint_family_wise) continue;
    between = true;
    const RecordVerdict each = record_verdict(m);
    const RecordVerdict whole = record_verdict(m, record_test_count(m));
    EXPECT_TRUE(each.loop_mismatch[0]);
    ASSERT_FALSE(each.located.empty());
    EXPECT_EQ(each.located.front(), std::make_pair(std::size_t{0}, std::size_t{0}));
    EXPECT_FALSE(whole.loop_mismatch[0]) << "LR " << lr << " under the family-wise limit " << family_wise;
    for (const auto& c : whole.located) EXPECT_NE(c.first, 0u);
  }
  ASSERT_TRUE(between) << "no planted gain put the LR between " << per_test << " and " << family_wise;
  const GrangerMonitor strong = record(0.5);
  EXPECT_TRUE(record_verdict(strong, record_test_count(strong)).loop_mismatch[0]);
}

}  // namespace
}  // namespace mpm
