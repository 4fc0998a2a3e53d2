// The whole live alarm path under no mismatch (closed loop, residual,
// monitor, sequential detector) against its stated false-alarm rate, and
// the paper's concealed mismatch raised live. The stated rate here is high
// (one alarm per 2e4 samples per controller) so that alarms are observable
// in a CI-sized run; scripts/calibrate_alarms.py runs the full version.
#include <cmath>
#include <cstdlib>
#include <string>

#include <gtest/gtest.h>

#include "config/plant_loader.hpp"
#include "core/chi_square.hpp"
#include "daemon/calibration.hpp"

namespace mpm {
namespace {

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kSanitized = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif
#else
constexpr bool kSanitized = false;
#endif

constexpr double kSamplesPerAlarm = 2e4;
constexpr double kSecondsPerYear = 365.25 * 86400.0;

PlantModel plant(const std::string& name) { return config::load_plant(std::string(MPM_SOURCE_DIR) + "/config/" + name); }

MonitorSettings live_settings(const PlantModel& p, double samples_per_alarm) {
  MonitorSettings s;  // mpmd's defaults (forgetting 0.999)
  s.detector.sample_time = p.sample_time;
  s.detector.false_alarms_per_year = kSecondsPerYear / (samples_per_alarm * p.sample_time);
  return s;
}

// 95 % interval of a Poisson mean from a count (exact, via chi-square).
std::pair<double, double> poisson_interval(std::size_t n) {
  const double lo = n == 0 ? 0.0 : 0.5 * chi_square_quantile_upper(0.975, 2.0 * static_cast<double>(n));
  const double hi = 0.5 * chi_square_quantile_upper(0.025, 2.0 * static_cast<double>(n + 1));
  return {lo, hi};
}

TEST(AlarmCalibration, NoMismatchRaisesAtTheStatedRatePerUnitTime) {
  struct Case {
    const char* file;
    int runs;
  };
  const int scale = kSanitized ? 1 : 3;
  const Case cases[] = {{"wood-berry.yaml", 2 * scale}, {"three-by-three.yaml", scale}, {"quad-tank.yaml", 2 * scale}};
  const std::size_t samples = 30000;
  std::size_t raises = 0, first_half = 0, monitored = 0;
  std::uint64_t seed = 101;
  for (const Case& c : cases) {
    const PlantModel p = plant(c.file);
    const MonitorSettings s = live_settings(p, kSamplesPerAlarm);
    for (int r = 0; r < c.runs; ++r) {
      const NullRun run = null_alarm_run(p, s, seed++, samples);
      monitored += run.samples;
      raises += run.raises.size();
      for (std::size_t k : run.raises) first_half += k < run.samples / 2 ? 1 : 0;
    }
  }
  const double expected = static_cast<double>(monitored) / kSamplesPerAlarm;
  const auto [lo, hi] = poisson_interval(raises);
  RecordProperty("raises", static_cast<int>(raises));
  std::printf("%zu raises in %zu samples: %.3g x the stated rate (95%% CI %.3g..%.3g); first half %zu\n", raises,
              monitored, static_cast<double>(raises) / expected, lo / expected, hi / expected, first_half);
  // Within a factor of 2 of the stated rate, or below it with an interval
  // that reaches it.
  EXPECT_LE(lo / expected, 2.0);
  EXPECT_GE(hi / expected, kSanitized ? 0.25 : 0.5);
  // Flat in time: the raises split between the halves of the runs as a fair
  // coin would (two-sided binomial, normal approximation, |z| < 3).
  if (raises >= 8) {
    const double z = (static_cast<double>(first_half) - 0.5 * static_cast<double>(raises)) /
                     std::sqrt(0.25 * static_cast<double>(raises));
    EXPECT_LT(std::abs(z), 3.0) << first_half << " of " << raises << " raises in the first half";
  }
}

TEST(AlarmCalibration, ConcealedG21GainMismatchIsRaisedLiveOnY2) {
  // The paper's Wood-Berry G21 x 1.2 under the MPC, at the shipped rate (one
  // false alarm per year): raised on y2, naming u1.
  const PlantModel p = plant("wood-berry.yaml");
  MonitorSettings s;
  int raised = 0, named = 0, within = 0;
  const int seeds = kSanitized ? 1 : 3;
  for (int seed = 1; seed <= seeds; ++seed) {
    const NullRun run = null_alarm_run(p, s, static_cast<std::uint64_t>(seed), 20000, {}, "wood-berry-g21-gain");
    bool y2 = false, u1 = false;
    // Within 2x the ~3000 samples the end-of-record test needs (issue 11);
    // seed 1 needs more, offline too (measured 7342 live).
    if (!run.raises.empty()) {
      std::printf("seed %d: first raise at sample %zu\n", seed, run.raises.front());
      within += run.raises.front() < 6000 ? 1 : 0;
    }
    for (std::size_t e = 0; e < run.raises.size(); ++e) {
      EXPECT_EQ(run.raised_outputs[e], 1u) << "seed " << seed << ": raised y1, which matches the model";
      if (run.raised_outputs[e] == 1) {
        y2 = true;
        u1 = u1 || run.raised_inputs[e] == 0;
      }
    }
    raised += y2 ? 1 : 0;
    named += u1 ? 1 : 0;
  }
  EXPECT_EQ(raised, seeds);
  EXPECT_EQ(named, seeds);
  EXPECT_GE(within, seeds - 1) << "raised within 6000 samples on too few seeds";
}

}  // namespace
}  // namespace mpm
