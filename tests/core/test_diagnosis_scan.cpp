// The diagnosis scan's schedule, level and raise/clear state
// (core/diagnosis_scan.hpp), and its sample ring.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/diagnosis_scan.hpp"

namespace mpm {
namespace {

ScanSettings small() {
  ScanSettings s;
  s.interval = 100;
  s.window = 400;
  s.min_samples = 250;
  s.clear_after = 2;
  return s;
}

TEST(DiagnosisScan, LooksAtMinSamplesThenEveryIntervalAndAfreshAfterARestart) {
  DiagnosisScan scan(2, small(), 1e-6);
  std::vector<int> due;
  std::vector<std::size_t> lengths;
  for (int k = 1; k <= 700; ++k) {
    if (scan.on_ready_sample()) {
      due.push_back(k);
      lengths.push_back(scan.look_length());
    }
  }
  EXPECT_EQ(due, (std::vector<int>{250, 350, 450, 550, 650}));
  // The window grows with the samples until it is full.
  EXPECT_EQ(lengths, (std::vector<std::size_t>{250, 350, 400, 400, 400}));
  EXPECT_EQ(scan.checkpoints(), 5u);
  scan.restart();
  int first = 0;
  for (int k = 1; k <= 300 && first == 0; ++k)
    if (scan.on_ready_sample()) first = k;
  EXPECT_EQ(first, 250);
  EXPECT_EQ(scan.look_length(), 250u);
}

TEST(DiagnosisScan, OffTakesNoShareAndNeverLooks) {
  ScanSettings off = small();
  off.interval = 0;
  DetectorSettings d;
  d.false_alarms_per_year = 10.0;
  d.sample_time = 1.0;
  EXPECT_EQ(share_rate(d, off, 1.0), 0.0);
  EXPECT_EQ(d.false_alarms_per_year, 10.0);
  DiagnosisScan scan(1, off, 0.0);
  for (int k = 0; k < 1000; ++k) EXPECT_FALSE(scan.on_ready_sample());
  EXPECT_FALSE(DiagnosisScan().enabled());
}

TEST(DiagnosisScan, LevelPerLookIsTheScanShareOfTheRateTimesTheInterval) {
  // One false alarm per 2e4 samples for the controller (sample time 5 s).
  DetectorSettings d;
  d.sample_time = 0.0;  // the plant's
  const double per_sample = 1.0 / 2e4;
  d.false_alarms_per_year = per_sample * 365.25 * 86400.0 / 5.0;
  ScanSettings s = small();
  s.share = 0.25;
  const double rate = share_rate(d, s, 5.0);
  EXPECT_DOUBLE_EQ(d.sample_time, 5.0);
  EXPECT_NEAR(rate, 0.25 * per_sample, 1e-15);
  EXPECT_NEAR(d.rate_per_sample(), 0.75 * per_sample, 1e-15);  // the sequential detector keeps the rest
  DiagnosisScan scan(1, s, rate);
  EXPECT_NEAR(scan.alpha_look(), 0.25 * per_sample * 100.0, 1e-15);
  // Over T samples the looks' levels sum to the share of the rate: the
  // union bound on the expected number of false looks.
  double sum = 0.0;
  for (int k = 0; k < 100000; ++k)
    if (scan.on_ready_sample()) sum += scan.alpha_look();
  EXPECT_LE(sum, 0.25 * per_sample * 100000.0 + 1e-12);
}

TEST(DiagnosisScan, RaisesAtAFindingAndClearsAfterCleanLooksInARow) {
  DiagnosisScan scan(2, small(), 1e-6);
  std::vector<std::pair<std::size_t, bool>> edges;
  const auto look = [&](bool y1, bool y2) {
    scan.conclude({y1, y2}, [&](std::size_t j, bool raised) { edges.emplace_back(j, raised); });
  };
  look(false, true);
  EXPECT_EQ(edges, (std::vector<std::pair<std::size_t, bool>>{{1, true}}));
  look(false, true);  // still raised: no new edge
  look(false, false);  // one clean look: hysteresis holds it
  EXPECT_EQ(edges.size(), 1u);
  EXPECT_TRUE(scan.raised(1));
  look(false, true);  // a finding resets the clean count
  look(false, false);
  EXPECT_TRUE(scan.raised(1));
  look(true, false);  // second clean look in a row on y2: cleared; y1 raised
  EXPECT_EQ(edges, (std::vector<std::pair<std::size_t, bool>>{{1, true}, {0, true}, {1, false}}));
  EXPECT_FALSE(scan.raised(1));
  EXPECT_TRUE(scan.raised(0));
  EXPECT_EQ(scan.looks(), 6u);
}

TEST(SampleRing, CopiesTheLastRowsOldestFirstAcrossTheWrap) {
  SampleRing ring(4, 1, 1);
  Eigen::MatrixXd out(4, 2);
  for (int k = 0; k < 6; ++k) {
    const double u = k, r = 10.0 * k;
    ring.record(&u, &r);
  }
  EXPECT_EQ(ring.filled(), 4u);
  ring.copy_last(3, out);
  EXPECT_EQ(out(0, 0), 3.0);
  EXPECT_EQ(out(1, 0), 4.0);
  EXPECT_EQ(out(2, 0), 5.0);
  EXPECT_EQ(out(2, 1), 50.0);
}

TEST(ScanSettings, ValidateNamesTheBadSetting) {
  ScanSettings s;
  EXPECT_EQ(s.validate(), "");
  s.interval = 10;
  EXPECT_NE(s.validate().find("scan_interval"), std::string::npos);
  s = ScanSettings{};
  s.min_samples = s.window + 1;
  EXPECT_NE(s.validate().find("min_samples"), std::string::npos);
}

}  // namespace
}  // namespace mpm
