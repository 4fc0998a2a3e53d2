// `mpm diagnose` and `mpm monitor` on an lcm-logger file of the sample
// channel give what they give on the CSV of the same samples (issue 14,
// item 3). The log is written through liblcm's writer with lcm-gen's
// encoder, as lcm-logger records `mpm replay`: the recording's columns as
// u, y and named extras (the setpoints), with events of another channel and
// a sample our decoder refuses between them; the file is named .csv to show
// the format is told by content.
#include <gtest/gtest.h>

#include <string>

#include "../transport/lcm_log_files.hpp"
#include "support/cli.hpp"

namespace {

using mpm::test::kMpm;
using mpm::test::run_captured;

const std::string kPlant = std::string(MPM_SOURCE_DIR) + "/config/wood-berry.yaml";

std::string tmp(const std::string& name) { return mpm::test::per_test_tmp_path("mpm_lcmdata_", name); }

// The simulated recording and the log of the same samples.
void write_pair(const std::string& csv, const std::string& log) {
  ASSERT_EQ(mpm::test::run_quietly(kMpm + " simulate --scenario wood-berry-g21-gain --samples 3000 --seed 1 --out " + csv), 0);
  const mpm::PlantModel plant = mpm::config::load_plant(kPlant);
  const auto samples = mpm::test::samples_of(plant, mpm::config::load_recording(csv));
  std::vector<mpm::test::LogEvent> events;
  for (std::size_t k = 0; k < samples.size(); ++k) {
    events.push_back({"MPM_SAMPLE", mpm::test::encode_sample(samples[k])});
    if (k % 100 == 7) events.push_back({"MPM_STATUS", {0xde, 0xad, 0xbe, 0xef}});
    if (k == 1234) events.push_back({"MPM_SAMPLE", {0xed, 0xa1, 0xda, 0x01, 0, 0, 0, 0, 0xff}});
  }
  mpm::test::write_lcm_log(log, events);
}

TEST(LcmLogData, DiagnoseGivesTheSameReportAsOnTheCsv) {
  const std::string csv = tmp("run.csv"), log = tmp("run-log.csv");
  write_pair(csv, log);
  const auto from_csv = run_captured(kMpm + " diagnose --plant " + kPlant + " --data " + csv, "csv");
  const auto from_log = run_captured(kMpm + " diagnose --plant " + kPlant + " --data " + log, "log");
  ASSERT_EQ(from_csv.exit_code, 0) << from_csv.err;
  ASSERT_EQ(from_log.exit_code, 0) << from_log.err;
  EXPECT_NE(from_csv.out.find("\"mismatch\": true"), std::string::npos);
  EXPECT_EQ(from_log.out, from_csv.out);
  // What was skipped is said once, in plain words.
  EXPECT_NE(from_log.err.find(log + ": LCM log, 3000 samples of MPM_SAMPLE from controller 'column-7' in 3031 events; "
                                    "30 events of other channels skipped; 1 malformed samples dropped (the first at event 1249 (byte "),
            std::string::npos)
      << from_log.err;
}

TEST(LcmLogData, MonitorStreamsTheLogAsItStreamsTheCsv) {
  const std::string csv = tmp("run.csv"), log = tmp("run.lcmlog");
  write_pair(csv, log);
  for (const char* threads : {"", " --threads 2"}) {
    const auto from_csv = run_captured(kMpm + " monitor --json --plant " + kPlant + " --data " + csv + threads, "csv");
    const auto from_log = run_captured(kMpm + " monitor --json --plant " + kPlant + " --data " + log + threads, "log");
    ASSERT_EQ(from_csv.exit_code, 0) << from_csv.err;
    ASSERT_EQ(from_log.exit_code, 0) << from_log.err;
    EXPECT_EQ(from_log.out, from_csv.out) << threads;
  }
  // Another channel name, through --channel: no sample there, a clear error.
  const auto none = run_captured(kMpm + " monitor --plant " + kPlant + " --data " + log + " --channel OTHER", "none");
  EXPECT_EQ(none.exit_code, 1);
  EXPECT_NE(none.err.find(log + ": no sample of channel 'OTHER' in 3031 events (other channels: MPM_SAMPLE, MPM_STATUS)"),
            std::string::npos)
      << none.err;
}

}  // namespace
