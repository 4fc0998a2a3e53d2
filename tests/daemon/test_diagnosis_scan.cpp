// The diagnosis scan in mpmd's service: on the closed-loop Wood-Berry column
// under its MPC, G21's time constant x 0.7 (gain kept: a mismatch the
// controller conceals, which the sequential detector raises late or not at
// all) is raised by the scan first, on y2 and u1, with the physics word, the
// fitted ratio and the held-out improvement; the nominal loop is not raised
// over several seeds.
// The looks run on the diagnosis thread; the test waits for it to be idle
// before the next sample (samples come far faster than in a plant, so
// without the wait looks would be skipped and the result would vary).
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>

#include "daemon/mpmd/monitor_service.hpp"
#include "sim/scenarios.hpp"

namespace mpm {
namespace {

struct ScanRun {
  std::vector<msg::Alarm> alarms;
  std::vector<msg::Diagnosis> diagnoses;
  std::vector<msg::Alarm> retired;  // published by the retire at the end
  std::uint64_t looks = 0;
};

// per_alarm > 0: the stated rate is one false alarm per that many samples.
// retire: the service is replaced at the end (a reload): its raised alarms are withdrawn.
ScanRun run(const char* scenario, std::uint64_t seed, std::size_t samples, double per_alarm = 0.0,
            bool retire = false) {
  const sim::Scenario* sc = sim::find_scenario(scenario);
  const PlantModel model = sim::default_plant(*sc).model;
  sim::ClosedLoop loop(model, sim::scenario_loop(*sc, model), seed);
  ServiceSettings settings;
  settings.controller_id = "wb";
  settings.monitor.forgetting = 0.999;  // mpmd's defaults
  settings.diagnosis_window = 3000;
  settings.scan_interval = 500;
  settings.log_interval = 3600;
  if (per_alarm > 0.0) settings.monitor.detector.false_alarms_per_year = 365.25 * 86400.0 / (per_alarm * model.sample_time);
  ScanRun out;
  MonitorService service(model, settings, [&](const msg::Alarm& a) { out.alarms.push_back(a); });
  msg::Sample s;
  s.controller_id = "wb";
  s.session_id = 1;
  for (std::size_t k = 0; k < samples; ++k) {
    const sim::LoopSample& ls = loop.step();
    s.seq = static_cast<std::int64_t>(k);
    s.u.assign(ls.u.begin(), ls.u.end());
    s.y.assign(ls.y.begin(), ls.y.end());
    service.on_sample(s, {});
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    do {
      service.poll_diagnoses([&](const msg::Diagnosis& d) { out.diagnoses.push_back(d); });
      if (service.diagnosis()->idle()) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    } while (std::chrono::steady_clock::now() < deadline);
  }
  EXPECT_EQ(service.scan().skipped(), 0u);
  out.looks = service.scan().looks();
  if (retire) {
    const std::size_t n = out.alarms.size();
    service.retire("reload");
    out.retired.assign(out.alarms.begin() + static_cast<std::ptrdiff_t>(n), out.alarms.end());
    out.alarms.resize(n);
  }
  return out;
}

bool from_scan(const msg::Alarm& a) { return a.text.rfind("diagnosis scan:", 0) == 0; }

TEST(DiagnosisScanService, RaisesAConcealedTimeConstantChangeFirstWithItsPhysics) {
  const ScanRun r = run("wood-berry-g21-time-constant", 1, 4000, 0.0, true);
  // The reload withdrew the scan's raise of y2 first.
  ASSERT_FALSE(r.retired.empty());
  const msg::Alarm& withdrawn = r.retired.front();
  EXPECT_TRUE(from_scan(withdrawn) && !withdrawn.raised && withdrawn.output == "y2") << withdrawn.text;
  EXPECT_NE(withdrawn.text.find("no longer watched"), std::string::npos) << withdrawn.text;
  EXPECT_GE(r.looks, 3u);
  ASSERT_FALSE(r.alarms.empty());
  const msg::Alarm& first = r.alarms.front();
  EXPECT_TRUE(from_scan(first) && first.raised) << first.text;
  EXPECT_EQ(first.output, "y2");
  EXPECT_EQ(first.input, "u1");
  EXPECT_EQ(first.physics, "time_constant") << first.text;
  EXPECT_GT(first.p_value, 0.0);  // the look's level
  EXPECT_LT(first.p_value, 1e-4);
  for (const msg::Alarm& a : r.alarms) {
    if (!from_scan(a)) {
      // The sequential detector, if at all, raises it later, and a raise of
      // the channel the scan has named carries the scan's word.
      EXPECT_GT(a.sample_sequence, first.sample_sequence) << a.text;
      if (a.raised && a.output == "y2" && a.input == "u1") {
        EXPECT_EQ(a.physics, "time_constant") << a.text;
      }
      continue;
    }
    EXPECT_TRUE(a.raised) << "the mismatch stays: no scan clear expected: " << a.text;
    EXPECT_EQ(a.output, "y2") << a.text;  // u1 -> y2 only
  }
  // The raise's finding follows as a diagnosis message, at the look's sample.
  const msg::Diagnosis* d = nullptr;
  for (const msg::Diagnosis& x : r.diagnoses)
    if (x.sample_sequence == first.sample_sequence) d = &x;
  ASSERT_NE(d, nullptr);
  EXPECT_TRUE(d->found);
  EXPECT_EQ(d->physics, "time_constant");
  bool has_ratio = false;
  for (std::size_t n = 0; n < d->parameter_names.size(); ++n) {
    if (d->parameter_names[n] != "time_constant_ratio") continue;
    has_ratio = true;
    EXPECT_NEAR(d->parameter_values[n], 0.7, 0.15) << d->text;  // the scenario's factor
  }
  EXPECT_TRUE(has_ratio) << d->text;
  EXPECT_GT(d->holdout_improvement, 0.0) << d->text;
  EXPECT_GT(d->window, 0);
}

TEST(DiagnosisScanService, TheNominalLoopIsNotRaised) {
  for (std::uint64_t seed : {2u, 3u, 4u}) {
    const ScanRun r = run("wood-berry-nominal", seed, 4000);
    EXPECT_GE(r.looks, 3u);
    for (const msg::Alarm& a : r.alarms) ADD_FAILURE() << "seed " << seed << ": " << a.text;
  }
}

// The whole live path (sequential detector + scan) at a stated rate high
// enough to observe: one false alarm per 2e4 samples. The full calibration
// (531 runs, three plants) is scripts/calibrate_alarms.py; here Wood-Berry
// no-mismatch closed loops, fewer under CI=true. The count must not be
// significantly above twice the stated one (one-sided Poisson test at 0.1 %),
// and the test prints it against the stated count.
TEST(DiagnosisScanService, WholePathFalseAlarmsStayNearTheStatedRate) {
  const bool ci = std::getenv("CI") != nullptr && std::string(std::getenv("CI")) == "true";
  const int runs = ci ? 6 : 16;
  const std::size_t samples = 10000;
  int raises = 0, by_scan = 0;
  for (int r = 0; r < runs; ++r) {
    const ScanRun run_r = run("wood-berry-nominal", 5000 + static_cast<std::uint64_t>(r), samples, 2e4);
    for (const msg::Alarm& a : run_r.alarms) {
      raises += a.raised ? 1 : 0;
      by_scan += a.raised && from_scan(a) ? 1 : 0;
    }
  }
  const double stated = runs * static_cast<double>(samples) / 2e4;
  // P(Poisson(2 x stated) >= k): the smallest k with tail < 1e-3.
  const double mu = 2.0 * stated;
  double term = std::exp(-mu), cdf = 0.0;
  int limit = 0;
  for (; cdf + term < 1.0 - 1e-3; ++limit) {
    cdf += term;
    term *= mu / (limit + 1);
  }
  std::printf("%d raises (%d by the scan) against %.1f stated over %d runs of %zu samples (limit %d)\n", raises,
              by_scan, stated, runs, samples, limit);
  EXPECT_LE(raises, limit);
}

}  // namespace
}  // namespace mpm
