// lcm-logger files as recordings (daemon/lcm_log_reader.hpp): the same
// rows as the CSV of the same samples; other channels, other controllers
// and samples our decoder refuses are counted, never rows; gaps become
// missing rows; a file that lies about its framing is an error naming the
// file, the event and its byte offset, before liblcm allocates.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <string>

#include "config/row_source.hpp"
#include "lcm_log_files.hpp"
#include "daemon/lcm_log_reader.hpp"

namespace mpm::transport {
namespace {

using test::LogEvent;

const PlantModel& wood_berry() {
  static const PlantModel p = config::load_plant(MPM_SOURCE_DIR "/config/wood-berry.yaml");
  return p;
}

std::string scratch(const std::string& name) {
  return ::testing::TempDir() + "mpm_lcm_log_" + std::to_string(::getpid()) + "_" + name;
}

// A recording with noise in every column, the extras an MPC might send.
config::Recording random_recording(int rows) {
  config::Recording rec;
  rec.names = {"t", "u1", "u2", "y1", "y2", "feed_temp", "r_y1"};
  rec.data.resize(rows, 7);
  std::mt19937_64 rng(5);
  std::normal_distribution<double> n;
  for (int k = 0; k < rows; ++k) {
    rec.data(k, 0) = k * wood_berry().sample_time;
    for (int c = 1; c < 7; ++c) rec.data(k, c) = 10 * c + n(rng);
  }
  return rec;
}

std::vector<LogEvent> sample_events(const std::vector<msg::Sample>& samples) {
  std::vector<LogEvent> events;
  for (const auto& s : samples) events.push_back({"MPM_SAMPLE", test::encode_sample(s)});
  return events;
}

bool same(double a, double b) { return (std::isnan(a) && std::isnan(b)) || a == b; }

TEST(LcmLogReader, GivesTheRowsOfTheCsvOfTheSameSamples) {
  const config::Recording csv = random_recording(200);
  const std::vector<msg::Sample> samples = test::samples_of(wood_berry(), csv);
  std::vector<LogEvent> events;
  for (std::size_t k = 0; k < samples.size(); ++k) {
    events.push_back({"MPM_SAMPLE", test::encode_sample(samples[k])});
    if (k % 10 == 3) events.push_back({"MPM_STATUS", {1, 2, 3, 4}});  // skipped, counted
    if (k == 50) {  // a sample our decoder refuses: dropped, no row, no hole
      std::vector<std::uint8_t> bad = test::encode_sample(samples[k]);
      bad.resize(bad.size() - 5);
      events.push_back({"MPM_SAMPLE", bad});
    }
  }
  const std::string path = scratch("same.lcmlog");
  test::write_lcm_log(path, events);
  ASSERT_TRUE(is_lcm_log(path));
  LcmLogCounts counts;
  const config::Recording log = load_lcm_log(path, wood_berry(), {}, &counts);
  EXPECT_EQ(log.names, csv.names);
  ASSERT_EQ(log.data.rows(), csv.data.rows());
  ASSERT_EQ(log.data.cols(), csv.data.cols());
  for (Eigen::Index k = 0; k < csv.data.size(); ++k) EXPECT_TRUE(same(log.data.data()[k], csv.data.data()[k])) << k;
  EXPECT_EQ(counts.samples, 200u);
  EXPECT_EQ(counts.other_channels, 20u);
  EXPECT_EQ(counts.malformed, 1u);
  EXPECT_NE(counts.first_malformed.find("event 57 (byte "), std::string::npos) << counts.first_malformed;
  EXPECT_EQ(counts.events, 221u);
  EXPECT_EQ(counts.missing_rows, 0u);
  std::remove(path.c_str());
}

TEST(LcmLogReader, GapsAreMissingRowsRepeatsAreDroppedARestartIsOneMissingRow) {
  std::vector<msg::Sample> s = test::samples_of(wood_berry(), random_recording(8));
  // seq 1, 2, 5 (two missing), 5 again, 3 (old), 6; then a new session from 1.
  const std::int64_t seqs[] = {1, 2, 5, 5, 3, 6, 1, 2};
  for (std::size_t k = 0; k < s.size(); ++k) s[k].seq = seqs[k];
  s[6].session_id = s[7].session_id = 99;
  s[3].controller_id = "other";  // a second controller on the channel: skipped
  s[3].seq = 5;
  const std::string path = scratch("gaps.lcmlog");
  test::write_lcm_log(path, sample_events(s));
  LcmLogRowReader reader(path, wood_berry());
  std::vector<std::vector<double>> rows;
  std::vector<double> row;
  while (reader.next(row)) rows.push_back(row);
  // rows: 1, 2, NaN, NaN, 5, 6, NaN (restart), 1', 2'
  ASSERT_EQ(rows.size(), 9u);
  const double ts = wood_berry().sample_time;
  for (std::size_t r = 0; r < rows.size(); ++r) EXPECT_EQ(rows[r][0], static_cast<double>(r) * ts);
  for (const std::size_t r : {2u, 3u, 6u}) EXPECT_TRUE(std::isnan(rows[r][1])) << r;
  EXPECT_EQ(rows[4][1], s[2].u[0]);
  EXPECT_EQ(rows[5][1], s[5].u[0]);
  EXPECT_EQ(rows[7][1], s[6].u[0]);
  const LcmLogCounts& c = reader.counts();
  EXPECT_EQ(c.samples, 6u);
  EXPECT_EQ(c.other_controllers, 1u);
  EXPECT_EQ(c.duplicates, 1u);
  EXPECT_EQ(c.restarts, 1u);
  EXPECT_EQ(c.missing_rows, 3u);
  EXPECT_NE(reader.notes().find("1 samples of other controllers skipped"), std::string::npos) << reader.notes();
  std::remove(path.c_str());
}

TEST(LcmLogReader, AHugeSequenceJumpResynchronisesInsteadOfFillingRows) {
  std::vector<msg::Sample> s = test::samples_of(wood_berry(), random_recording(3));
  s[1].seq = 1'000'000'000'000'000;
  s[2].seq = s[1].seq + 1;
  const std::string path = scratch("jump.lcmlog");
  test::write_lcm_log(path, sample_events(s));
  LcmLogCounts counts;
  const config::Recording rec = load_lcm_log(path, wood_berry(), {}, &counts);
  EXPECT_EQ(rec.samples(), 4u);  // 1, NaN, 10^15, 10^15 + 1
  EXPECT_EQ(counts.resyncs, 1u);
  std::remove(path.c_str());
}

// The error message of loading `bytes` as a log.
std::string load_error(const std::string& name, const std::string& bytes) {
  const std::string path = scratch(name);
  std::ofstream(path, std::ios::binary) << bytes;
  std::string what;
  try {
    (void)load_lcm_log(path, wood_berry());
  } catch (const config::ConfigError& e) {
    what = e.what();
  }
  std::remove(path.c_str());
  return what;
}

std::string file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

bool printable(const std::string& text) {
  for (const char c : text)
    if (c < 0x20 || c == 0x7f) return false;
  return true;
}

TEST(LcmLogReader, BrokenFramingIsALocatedErrorWithoutBinaryJunk) {
  const std::vector<msg::Sample> s = test::samples_of(wood_berry(), random_recording(3));
  const std::string path = scratch("frames.lcmlog");
  test::write_lcm_log(path, sample_events(s));
  const std::string good = file_bytes(path);
  std::remove(path.c_str());
  const std::size_t frame = good.size() / 3;  // the three events have the same size

  const std::string cut = load_error("cut.lcmlog", good.substr(0, good.size() - 7));
  EXPECT_NE(cut.find("cut.lcmlog: event 3 (byte " + std::to_string(2 * frame) + "): truncated"), std::string::npos)
      << cut;
  const std::string junk = load_error("junk.lcmlog", good.substr(0, frame) + "\x01\xff junk \x7f" + good.substr(frame));
  EXPECT_NE(junk.find("event 2 (byte " + std::to_string(frame) + "): no event sync word"), std::string::npos) << junk;
  std::string huge = good;
  huge[frame + 24] = '\x7f';  // the second event's data length: 2^31 - something
  const std::string big = load_error("huge.lcmlog", huge);
  EXPECT_NE(big.find("event 2 (byte " + std::to_string(frame) + "): data length"), std::string::npos) << big;
  const std::string sync = load_error("sync.lcmlog", "X" + good.substr(1));
  EXPECT_NE(sync.find("event 1 (byte 0): no event sync word"), std::string::npos) << sync;
  for (const auto& e : {cut, junk, big, sync}) EXPECT_TRUE(printable(e)) << e;
}

TEST(LcmLogReader, ALogWithoutOurChannelNamesTheChannelsItHas) {
  const std::string path = scratch("other.lcmlog");
  test::write_lcm_log(path, {{"POSE", {1, 2}}, {std::string("BIN\x01\xfe", 5), {3}}});
  std::string what;
  try {
    LcmLogRowReader reader(path, wood_berry());
  } catch (const config::ConfigError& e) {
    what = e.what();
  }
  EXPECT_NE(what.find(path + ": no sample of channel 'MPM_SAMPLE' in 2 events (other channels: BIN??, POSE)"),
            std::string::npos)
      << what;
  std::remove(path.c_str());
}

TEST(LcmLogReader, TheFormatIsToldByContentNotByName) {
  const std::string csv = scratch("log.lcmlog");
  std::ofstream(csv) << "t,u1,u2,y1,y2\n0,1,2,3,4\n";
  EXPECT_FALSE(is_lcm_log(csv));
  const std::string log = scratch("data.csv");
  test::write_lcm_log(log, sample_events(test::samples_of(wood_berry(), random_recording(2))));
  EXPECT_TRUE(is_lcm_log(log));
  EXPECT_FALSE(is_lcm_log(scratch("does-not-exist")));
  std::remove(csv.c_str());
  std::remove(log.c_str());
}

}  // namespace
}  // namespace mpm::transport
