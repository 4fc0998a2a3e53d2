// Granger monitor on planted truth: simulated residuals with known causal
// links, checked for exactly those links; calibration of the test under H0;
// gaps; and zero heap allocation per update.
#include <cmath>
#include <cstdio>
#include <random>

#include <gtest/gtest.h>

#include "core/granger_monitor.hpp"
#include "core/noise_filter.hpp"
#include "support/sqrt_rls.hpp"
#include "core/transfer_function.hpp"
#include "support/alloc_counter.hpp"

namespace mpm {
namespace {

// Two inputs, two residuals d_j = sum_i dG_ji u_i + N_j a_j. Inputs are
// random-walk-ish excitation; u2 follows u1 (as closed-loop inputs do) unless
// `independent`.
struct PlantedRun {
  std::mt19937_64 rng;
  std::normal_distribution<double> n{0.0, 1.0};
  std::vector<std::vector<std::optional<DiscreteFilter>>> dg;  // [output][input]
  std::vector<DiscreteFilter> noise;
  DiscreteFilter coupling{DiscreteTf{{0.6}, {1, -0.7}, 1}};
  DiscreteFilter u1_shape{DiscreteTf{{1}, {1, -0.8}, 0}};
  bool independent = false;
  double u[2] = {0, 0};
  double d[2] = {0, 0};

  explicit PlantedRun(unsigned seed) : rng(seed), dg(2, std::vector<std::optional<DiscreteFilter>>(2)) {
    noise.emplace_back(DiscreteTf{{1}, {1, -0.8}, 0});
    noise.emplace_back(DiscreteTf{{1}, {1, -0.9}, 0});
  }
  // n samples of this run into the monitor.
  void feed(GrangerMonitor& m, int n_samples) {
    for (int k = 0; k < n_samples; ++k) {
      step();
      m.update(u, d);
    }
  }
  void step() {
    u[0] = u1_shape.step(n(rng));
    const double own = n(rng);
    u[1] = independent ? own : coupling.step(u[0]) + 0.5 * own;
    for (int j = 0; j < 2; ++j) {
      d[j] = noise[static_cast<std::size_t>(j)].step(n(rng));
      for (int i = 0; i < 2; ++i) {
        if (auto& f = dg[static_cast<std::size_t>(j)][static_cast<std::size_t>(i)]) d[j] += f->step(u[i]);
      }
    }
  }
};

std::vector<std::optional<std::vector<double>>> wood_berry_noise(int order) {
  return {inverse_noise_ar_coefficients(DiscreteTf{{1}, {1, -0.8}, 0}, order),
          inverse_noise_ar_coefficients(DiscreteTf{{1}, {1, -0.9}, 0}, order)};
}

MonitorSettings test_settings() { return {.ar_order = 5, .input_order = 6, .forgetting = 0.998}; }

TEST(GrangerMonitor, NoMismatchRaisesNothing) {
  PlantedRun run(1);
  GrangerMonitor m(2, 2, test_settings(), wood_berry_noise(5));
  for (int k = 0; k < 5000; ++k) {
    run.step();
    m.update(run.u, run.d);
    for (std::size_t j = 0; j < 2; ++j) ASSERT_FALSE(m.loop(j).alarm) << "k=" << k << " output " << j;
  }
  EXPECT_TRUE(m.ready());
  EXPECT_NEAR(m.loop(0).sigma1, 1.0, 0.2);  // AR part whitens N a: var(a) = 1
}

TEST(GrangerMonitor, LocatesThePlantedChannelDespiteCorrelatedInputs) {
  PlantedRun run(2);
  run.dg[1][0] = DiscreteFilter(DiscreteTf{{0.3}, {1, -0.8}, 2});  // mismatch u1 -> y2 only
  GrangerMonitor m(2, 2, test_settings(), wood_berry_noise(5));
  run.feed(m, 5000);
  EXPECT_TRUE(m.channel(1, 0).alarm);
  EXPECT_FALSE(m.channel(1, 1).alarm);
  EXPECT_FALSE(m.channel(0, 0).alarm);
  EXPECT_FALSE(m.channel(0, 1).alarm);
  EXPECT_TRUE(m.loop(1).alarm);
  EXPECT_FALSE(m.loop(0).alarm);
  // u2 follows u1, so the paper's one-input-at-a-time index sees u2 as well;
  // the conditional index does not.
  EXPECT_GT(m.channel(1, 1).lr_pairwise, m.raise_threshold());
  EXPECT_LT(m.channel(1, 1).lr_conditional, m.raise_threshold());
  // Noise-model index: the AR part with u1 in the model matches N^-1.
  EXPECT_LT(m.channel(1, 0).gamma, 0.01);
  EXPECT_LT(m.p_value(m.channel(1, 0).lr_conditional), 1e-6);
}

TEST(GrangerMonitor, ConditionalTestIsCalibratedUnderNoCausality) {
  // Under H0 the conditional LR is chi-square(nb): the fraction of tests above
  // the alpha = 5 % quantile must be close to 5 %.
  MonitorSettings s = test_settings();
  s.false_alarm = 0.05;
  s.forgetting = 1.0;
  int above = 0, total = 0;
  for (unsigned seed = 100; seed < 160; ++seed) {
    PlantedRun run(seed);
    run.independent = true;
    GrangerMonitor m(2, 2, s);
    run.feed(m, 1500);
    for (std::size_t j = 0; j < 2; ++j)
      for (std::size_t i = 0; i < 2; ++i) {
        above += m.channel(j, i).lr_conditional > m.raise_threshold();
        ++total;
      }
  }
  const double rate = static_cast<double>(above) / total;  // 240 tests, expected 12
  EXPECT_GT(rate, 0.01);
  EXPECT_LT(rate, 0.11);
}

// Model-filtered regressors of a slow channel (pole 0.995: 1 % after 919
// samples). At the first start the monitor waits for the filters' memory
// unless told the residual starts settled; after a gap it waits either way,
// and reset() makes the next sample a first start again.
TEST(GrangerMonitor, ASettledStartUsesRowsOnceTheLagsAreFilled) {
  std::vector<std::optional<DiscreteTf>> channels;
  for (int c = 0; c < 4; ++c) channels.emplace_back(DiscreteTf{{0.005}, {1, -0.995}, 1});
  const MonitorSettings s = test_settings();
  const int lags = std::max(s.ar_order, s.input_order);
  const auto used_after = [&](GrangerMonitor& m, PlantedRun& run, int n) {
    const std::uint64_t before = m.counters().used;
    run.feed(m, n);
    return m.counters().used - before;
  };
  PlantedRun run(5);
  GrangerMonitor waiting(2, 2, s, wood_berry_noise(5), {}, channels);
  EXPECT_EQ(used_after(waiting, run, 600), 0u) << "the wait for the filters' memory at the first start";
  GrangerMonitor settled(2, 2, s, wood_berry_noise(5), {}, channels);
  settled.start_settled();
  EXPECT_EQ(used_after(settled, run, 600), static_cast<std::uint64_t>(600 - lags));
  // A gap: the filters restart at rest while the plant goes on answering.
  const double gap_u[2] = {NAN, NAN}, gap_d[2] = {NAN, NAN};
  settled.update(gap_u, gap_d);
  EXPECT_EQ(used_after(settled, run, 600), 0u);
  settled.reset();
  EXPECT_EQ(used_after(settled, run, 100), static_cast<std::uint64_t>(100 - lags));
}

TEST(GrangerMonitor, GapsAreSkippedCountedAndRecovered) {
  PlantedRun run(3);
  run.dg[1][0] = DiscreteFilter(DiscreteTf{{0.3}, {1, -0.8}, 2});
  GrangerMonitor m(2, 2, test_settings(), wood_berry_noise(5));
  int missing = 0;
  for (int k = 0; k < 6000; ++k) {
    run.step();
    double d[2] = {run.d[0], run.d[1]};
    if (k % 1000 >= 500 && k % 1000 < 503) {  // three NaN samples every 1000
      d[k % 2] = NAN;
      ++missing;
    }
    const SampleStatus st = m.update(run.u, d);
    if (std::isnan(d[0]) || std::isnan(d[1])) {
      EXPECT_EQ(st, SampleStatus::kMissing);
    }
  }
  EXPECT_EQ(m.counters().missing, static_cast<std::uint64_t>(missing));
  EXPECT_EQ(m.counters().gaps, 6u);
  EXPECT_EQ(m.counters().samples, 6000u);
  EXPECT_TRUE(std::isfinite(m.loop(1).sigma_full));
  EXPECT_TRUE(m.channel(1, 0).alarm);
  EXPECT_FALSE(m.channel(0, 0).alarm);
}

TEST(GrangerMonitor, AlarmClearsWhenTheMismatchGoes) {
  PlantedRun run(4);
  run.dg[1][0] = DiscreteFilter(DiscreteTf{{0.3}, {1, -0.8}, 2});
  MonitorSettings s = test_settings();
  s.forgetting = 0.99;  // short memory so the verdict follows the plant
  GrangerMonitor m(2, 2, s, wood_berry_noise(5));
  run.feed(m, 3000);
  ASSERT_TRUE(m.channel(1, 0).alarm);
  run.dg[1][0].reset();
  // The output clears when every detector window has forgotten the
  // mismatch: within a few memories of the longest one (12800 samples here).
  const double longest = m.detector().window(m.detector().windows() - 1);
  int cleared_at = -1;
  for (int k = 0; k < static_cast<int>(4 * longest) && cleared_at < 0; ++k) {
    run.step();
    m.update(run.u, run.d);
    if (!m.channel(1, 0).alarm) cleared_at = k;
  }
  EXPECT_GE(cleared_at, 0) << "alarm never cleared";
  EXPECT_FALSE(m.loop(1).alarm);
}

TEST(GrangerMonitor, DivergingLoopIsFlaggedNotAnalysed) {
  PlantedRun run(5);
  GrangerMonitor m(2, 2, test_settings(), wood_berry_noise(5));
  double growth = 1.0;
  for (int k = 0; k < 3000; ++k) {
    run.step();
    if (k > 1000) growth *= 1.005;
    double d[2] = {run.d[0], run.d[1] + growth * run.u[0]};
    m.update(run.u, d);
  }
  EXPECT_TRUE(m.loop(1).diverging);
  EXPECT_FALSE(m.loop(1).alarm);
  EXPECT_FALSE(m.loop(0).diverging);
}

// With forgetting, "diverging" follows the residual: a stretch of values
// x 1e-8 (a quiet or dead sensor) or x 1e8 once left the flag set for good
// (no verdict ever again), found by the soak (tests/daemon/test_soak.cpp).
// After either, the flag clears (after a quiet stretch once the baseline,
// rising by 1/lambda per sample, is within 1e3 of the level again:
// ln(1e13) / (1 - lambda) = 15 000 samples here), and a later mismatch is
// raised.
TEST(GrangerMonitor, AQuietOrLoudStretchDoesNotBlindTheLiveMonitor) {
  for (const double scale : {1e-8, 1e8}) {
    PlantedRun run(8);
    GrangerMonitor m(2, 2, test_settings(), wood_berry_noise(5));
    for (int k = 0; k < 22000; ++k) {
      run.step();
      const double f = k >= 2000 && k < 4000 ? scale : 1.0;
      double u[2] = {f * run.u[0], f * run.u[1]};
      double d[2] = {f * run.d[0], f * run.d[1]};
      m.update(u, d);
    }
    EXPECT_FALSE(m.loop(0).diverging) << scale;
    EXPECT_FALSE(m.loop(1).diverging) << scale;
    run.dg[1][0] = DiscreteFilter(DiscreteTf{{0.5}, {1, -0.8}, 2});
    bool raised = false;
    for (int k = 0; k < 3000 && !raised; ++k) {
      run.step();
      m.update(run.u, run.d);
      raised = m.channel(1, 0).alarm;
    }
    EXPECT_TRUE(raised) << scale << ": the mismatch after the stretch was not raised";
  }
}

// Held inputs (a frozen actuator, a controller in manual) carry no
// excitation: the inputs' information decays to the prior while the score
// stops moving. When the inputs move again, every window must still be
// normalised by the information its own score accumulated. The soak found
// false raises 80..280 samples after frozen inputs moved again (9 of 100
// stretches): the long window's information was built from snapshots of the
// factor's S / n, which after a loss of excitation lags the information
// the score gathers (S has a memory of 1 / (1 - lambda) samples), so the
// long window's T was inflated for its first refreshes.
TEST(GrangerMonitor, FrozenInputsMovingAgainRaiseNothing) {
  MonitorSettings s;  // the soak's: short memories, two windows
  s.ar_order = 5;
  s.input_order = 10;
  s.forgetting = 0.995;
  s.detector.windows = 2;
  // Cycles of 3000 moving samples and 5000 held (S and J_W forget the
  // inputs' information: lambda^5000 ~ 1e-11, rho_W^10000 ~ 2e-3).
  const int cycles = 60;
  int raises = 0, raises_frozen = 0;
  std::mt19937_64 rng(5);
  std::normal_distribution<double> n(0.0, 1.0);
  GrangerMonitor m(2, 2, s, wood_berry_noise(5));
  double noise[2] = {0.0, 0.0}, du[2] = {0.0, 0.0};
  bool was_raised = false;
  for (int c = 0; c < cycles; ++c) {
    for (int k = 0; k < 8000; ++k) {
      const bool frozen = c > 0 && k < 5000;
      if (!frozen) du[0] = 5.0 * n(rng), du[1] = 5.0 * n(rng);
      noise[0] = 0.8 * noise[0] + n(rng);
      noise[1] = 0.9 * noise[1] + n(rng);
      const double u[2] = {15.0 + du[0], 12.0 + du[1]};
      m.update(u, noise);
      const bool raised = m.loop(0).alarm || m.loop(1).alarm;
      if (raised && !was_raised) {
        (frozen ? raises_frozen : raises) += 1;
        std::printf("raise: cycle %d sample %d (%s) score %.1f threshold %.1f window %.0f\n", c, k,
                    frozen ? "frozen" : "moving", m.loop(m.loop(0).alarm ? 0 : 1).score,
                    m.loop(m.loop(0).alarm ? 0 : 1).score_threshold, m.loop(m.loop(0).alarm ? 0 : 1).score_window);
      }
      was_raised = raised;
    }
  }
  EXPECT_EQ(raises, 0) << "false raises on a matched plant after frozen inputs moved again (" << cycles << " cycles)";
  EXPECT_EQ(raises_frozen, 0);
}

TEST(GrangerMonitor, OneOutlierIsSkippedCountedAndForgotten) {
  // A single 1e6 spike in a residual (a sensor glitch) used to keep the loop
  // "diverging" for thousands of samples: it is now skipped and counted.
  PlantedRun run(6);
  GrangerMonitor m(2, 2, test_settings(), wood_berry_noise(5));
  run.feed(m, 3000);
  const double sigma_before = m.loop(0).sigma1;
  run.step();
  double d[2] = {run.d[0] + 1e6, run.d[1]};
  EXPECT_EQ(m.update(run.u, d), SampleStatus::kOutlier);
  EXPECT_EQ(m.counters().outliers, 1u);
  int diverging = 0;
  for (int k = 0; k < 300; ++k) {
    run.step();
    m.update(run.u, run.d);
    diverging += m.loop(0).diverging ? 1 : 0;
  }
  EXPECT_EQ(diverging, 0);
  EXPECT_LT(m.loop(0).sigma1, 2.0 * sigma_before) << "the spike must not enter the statistics";
  EXPECT_FALSE(m.loop(0).alarm);
}

TEST(GrangerMonitor, HugeValuesLeaveNoNaNBehind) {
  // 1e100 once (skipped as an outlier), then 1e300 held long enough to be
  // accepted as a level (the factor overflows): the output restarts from
  // its prior, counted, and its statistics are finite again.
  PlantedRun run(7);
  GrangerMonitor m(2, 2, test_settings(), wood_berry_noise(5));
  run.feed(m, 2000);
  run.step();
  double d[2] = {run.d[0], 1e100};
  m.update(run.u, d);
  for (int k = 0; k < 10; ++k) {
    run.step();
    double big[2] = {run.d[0], 1e300};
    m.update(run.u, big);
  }
  run.feed(m, 3000);
  EXPECT_GE(m.counters().outliers, 1u);
  EXPECT_GE(m.counters().resets, 1u);
  for (std::size_t j = 0; j < 2; ++j) {
    EXPECT_TRUE(std::isfinite(m.loop(j).sigma1)) << j;
    EXPECT_TRUE(std::isfinite(m.loop(j).sigma_full)) << j;
    EXPECT_TRUE(std::isfinite(m.loop(j).lr_joint)) << j;
    for (std::size_t i = 0; i < 2; ++i) EXPECT_TRUE(std::isfinite(m.channel(j, i).lr_conditional)) << j << i;
  }
}

TEST(GrangerMonitor, UpdateAllocatesNothing) {
  MonitorSettings s;  // defaults: na = nb = 10
  GrangerMonitor m(2, 2, s, wood_berry_noise(10));
  PlantedRun run(6);
  run.dg[1][0] = DiscreteFilter(DiscreteTf{{0.3}, {1, -0.8}, 2});
  run.feed(m, 100);  // warm the lags (not counted)
  std::vector<double> us, ds;  // pre-generated so only update() is measured
  for (int k = 0; k < 100'000; ++k) {
    run.step();
    us.insert(us.end(), run.u, run.u + 2);
    ds.insert(ds.end(), run.d, run.d + 2);
  }
  ds[2 * 5000] = NAN;  // exercise the gap path too
  long allocations = 0;
  {
    test::AllocationScope scope;
    for (std::size_t k = 0; k < 100'000; ++k) m.update(&us[2 * k], &ds[2 * k]);
    allocations = scope.count();
  }
  EXPECT_EQ(allocations, 0);
  // Every sample is used except the lag fill at the start (10), the NaN
  // sample and the lag refill after it (10).
  EXPECT_EQ(m.counters().used, 100u + 100'000u - 10u - 1u - 10u);
}

// The statistics equal independent least-squares fits of the same regressor
// rows: the pairwise models (the first input's is a prefix of the full
// model's factor) and the conditional RSS (re-triangularisation below 4
// inputs, the Wald identity on the tracked inverse from 4 on).
void expect_matches_reference_fits(std::size_t m) {
  MonitorSettings s;
  s.ar_order = 3;
  s.input_order = 4;
  s.forgetting = 1.0;
  const std::size_t na = 3, nb = 4, p_full = 1 + na + m * nb, p_pair = 1 + na + nb;
  GrangerMonitor monitor(m, 1, s);
  SqrtRls full(p_full, 1.0, 1e-9);
  std::vector<SqrtRls> pair(m, SqrtRls(p_pair, 1.0, 1e-9));
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n(0.0, 1.0);
  std::vector<std::vector<double>> u_hist(m);
  std::vector<double> d_hist;
  std::vector<double> u(m), x(p_full), xp(p_pair);
  for (std::size_t k = 0; k < 3000; ++k) {
    for (std::size_t i = 0; i < m; ++i) u[i] = n(rng) + (i > 0 ? 0.5 * u[0] : 0.0);
    double d = 0.3 * n(rng) + (k > 0 ? 0.5 * d_hist[k - 1] : 0.0) + (k > 1 ? 0.4 * u_hist[0][k - 2] : 0.0);
    ASSERT_EQ(monitor.update(u.data(), &d), k >= 4 ? SampleStatus::kUsed : SampleStatus::kWarmingUp);
    for (std::size_t i = 0; i < m; ++i) u_hist[i].push_back(u[i]);
    d_hist.push_back(d);
    if (k < 4) continue;
    // Regressors: intercept, d(k-1..k-na), u_i(k-1..k-nb) about u_i(0).
    x[0] = xp[0] = 1.0;
    for (std::size_t l = 1; l <= na; ++l) x[l] = xp[l] = d_hist[k - l];
    for (std::size_t i = 0; i < m; ++i)
      for (std::size_t l = 1; l <= nb; ++l) x[na + i * nb + l] = u_hist[i][k - l] - u_hist[i][0];
    full.update(x.data(), d);
    for (std::size_t i = 0; i < m; ++i) {
      std::copy(x.begin() + static_cast<long>(1 + na + i * nb), x.begin() + static_cast<long>(1 + na + (i + 1) * nb),
                xp.begin() + static_cast<long>(1 + na));
      pair[i].update(xp.data(), d);
    }
  }
  SqrtRls::Matrix scratch(static_cast<Eigen::Index>(p_full + 1), static_cast<Eigen::Index>(p_full + 1));
  const auto close = [](double a, double ref) { return std::abs(a - ref) <= 1e-8 * std::abs(ref) + 1e-12; };
  for (std::size_t i = 0; i < m; ++i) {
    const double f_cond = std::log(full.rss_without(1 + na + i * nb, nb, scratch) / full.rss());
    const double f_pair = std::log(pair[i].rss_prefix(1 + na) / pair[i].rss());
    EXPECT_PRED2(close, monitor.channel(0, i).f_conditional, f_cond) << "m=" << m << " input " << i;
    EXPECT_PRED2(close, monitor.channel(0, i).f_pairwise, f_pair) << "m=" << m << " input " << i;
  }
  EXPECT_GT(monitor.channel(0, 0).lr_conditional, monitor.raise_threshold());  // the planted link is seen
}

TEST(GrangerMonitor, StatisticsEqualReferenceFits) {
  expect_matches_reference_fits(2);  // re-triangularisation
  expect_matches_reference_fits(4);  // Wald identity
  expect_matches_reference_fits(6);
}

// Monitors of one output each, fed the same whole samples (with a gap, and
// with model-filtered regressors of different settling times per output),
// reproduce the whole monitor bit for bit, and merged back they are it.
TEST(GrangerMonitor, PartsOfTheOutputsEqualTheWholeMonitor) {
  const MonitorSettings s = test_settings();
  // Channel models: output 2's settle far longer than output 1's, so a part
  // that took only its own into account would restart differently.
  const std::vector<std::optional<DiscreteTf>> channels = {
      DiscreteTf{{0.5}, {1, -0.5}, 1}, DiscreteTf{{0.3}, {1, -0.6}, 2},
      DiscreteTf{{0.2}, {1, -0.97}, 1}, std::nullopt};
  GrangerMonitor whole(2, 2, s, wood_berry_noise(s.ar_order), {}, channels);
  GrangerMonitor first(2, 2, s, wood_berry_noise(s.ar_order), {}, channels, OutputRange{0, 1});
  GrangerMonitor second(2, 2, s, wood_berry_noise(s.ar_order), {}, channels, OutputRange{1, 5});
  EXPECT_EQ(second.end_modelled_output(), 2u);  // clipped to the plant
  PlantedRun run(5);
  run.dg[1][0].emplace(DiscreteTf{{0.4}, {1, -0.6}, 2});
  for (int k = 0; k < 6000; ++k) {
    run.step();
    double d[2] = {run.d[0], run.d[1]};
    if (k == 3000) d[0] = NAN;  // a gap in one residual skips the sample for all
    whole.update(run.u, d);
    first.update(run.u, d);
    second.update(run.u, d);
  }
  EXPECT_EQ(whole.counters().missing, 1u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(first.channel(0, i).lr_conditional, whole.channel(0, i).lr_conditional);
    EXPECT_EQ(first.channel(0, i).gamma, whole.channel(0, i).gamma);
    EXPECT_EQ(second.channel(1, i).lr_conditional, whole.channel(1, i).lr_conditional);
    EXPECT_EQ(second.channel(1, i).f_pairwise, whole.channel(1, i).f_pairwise);
    EXPECT_EQ(second.channel(1, i).alarm, whole.channel(1, i).alarm);
  }
  EXPECT_EQ(second.loop(1).lr_joint, whole.loop(1).lr_joint);
  EXPECT_TRUE(whole.channel(1, 0).alarm);  // the planted channel: a real check
  EXPECT_EQ(first.channel(1, 0).lr_conditional, 0.0);  // not modelled there

  GrangerMonitor merged(2, 2, s, wood_berry_noise(s.ar_order), {}, channels);
  merged.adopt_outputs(first);
  merged.adopt_outputs(second);
  EXPECT_EQ(merged.channel(1, 0).lr_conditional, whole.channel(1, 0).lr_conditional);
  EXPECT_EQ(merged.counters().used, whole.counters().used);
  // And it goes on exactly as the whole one.
  for (int k = 0; k < 200; ++k) {
    run.step();
    whole.update(run.u, run.d);
    merged.update(run.u, run.d);
  }
  EXPECT_EQ(merged.channel(1, 0).lr_conditional, whole.channel(1, 0).lr_conditional);
  EXPECT_EQ(merged.channel(0, 1).gamma, whole.channel(0, 1).gamma);
  GrangerMonitor other(2, 2, test_settings(), {}, {}, {});  // no channel models: settles differently
  EXPECT_THROW(other.adopt_outputs(first), std::invalid_argument);
}

// The RSS-based statistics are computed when read (refresh_statistics):
// a monitor read only now and then shows, at each read, exactly what a
// monitor read after every sample shows, across warm-up, a gap, an outlier
// and a raise; and reading them allocates nothing.
TEST(GrangerMonitor, StatisticsReadLateEqualStatisticsReadEverySample) {
  const MonitorSettings s = test_settings();
  GrangerMonitor every(2, 2, s, wood_berry_noise(s.ar_order));
  GrangerMonitor late(2, 2, s, wood_berry_noise(s.ar_order));
  PlantedRun run(11);
  run.dg[1][0].emplace(DiscreteTf{{0.4}, {1, -0.6}, 2});
  std::vector<double> us, ds;
  for (int k = 0; k < 8000; ++k) {
    run.step();
    us.insert(us.end(), run.u, run.u + 2);
    ds.insert(ds.end(), run.d, run.d + 2);
  }
  ds[2 * 3000] = NAN;            // a gap
  ds[2 * 5000 + 1] += 1e3;       // an outlier
  std::vector<ChannelStats> seen(4);
  std::vector<LoopStats> seen_loop(2);
  int compared = 0;
  long allocations = 0;
  for (std::size_t k = 0; k < 8000; ++k) {
    every.update(&us[2 * k], &ds[2 * k]);
    {
      test::AllocationScope scope;
      for (std::size_t j = 0; j < 2; ++j) {
        seen_loop[j] = every.loop(j);
        for (std::size_t i = 0; i < 2; ++i) seen[j * 2 + i] = every.channel(j, i);
      }
      allocations += scope.count();
    }
    late.update(&us[2 * k], &ds[2 * k]);
    if (k % 997 != 0 && k != 3000 && k != 3001 && k != 5000 && k != 7999) continue;
    ++compared;
    for (std::size_t j = 0; j < 2; ++j) {
      EXPECT_EQ(late.loop(j).lr_joint, seen_loop[j].lr_joint) << "sample " << k;
      EXPECT_EQ(late.loop(j).residual_variance, seen_loop[j].residual_variance) << "sample " << k;
      for (std::size_t i = 0; i < 2; ++i) {
        const ChannelStats& c = late.channel(j, i);
        EXPECT_EQ(c.f_conditional, seen[j * 2 + i].f_conditional) << "sample " << k;
        EXPECT_EQ(c.lr_pairwise, seen[j * 2 + i].lr_pairwise) << "sample " << k;
        EXPECT_TRUE(c.gamma == seen[j * 2 + i].gamma || (std::isnan(c.gamma) && std::isnan(seen[j * 2 + i].gamma)))
            << "sample " << k;
        EXPECT_EQ(c.alarm, seen[j * 2 + i].alarm) << "sample " << k;
      }
    }
  }
  EXPECT_EQ(compared, 13);
  EXPECT_EQ(allocations, 0);
  EXPECT_EQ(late.counters().outliers, 1u);
  EXPECT_TRUE(late.channel(1, 0).alarm);  // the planted channel raised: a real run
  EXPECT_GT(late.channel(1, 0).lr_conditional, late.raise_threshold());
}

TEST(MonitorSettings, ValidateNamesTheField) {
  MonitorSettings s;
  s.forgetting = 1.5;
  EXPECT_NE(s.validate().find("forgetting"), std::string::npos);
  EXPECT_THROW(GrangerMonitor(2, 2, s), std::invalid_argument);
  s = MonitorSettings{};
  s.input_order = 0;
  EXPECT_NE(s.validate().find("input_order"), std::string::npos);
  EXPECT_EQ(MonitorSettings{}.validate(), "");
}

}  // namespace
}  // namespace mpm
