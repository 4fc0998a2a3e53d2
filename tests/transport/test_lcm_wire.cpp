// Our decoder of mpm_lcm.sample_t (transport/lcm_wire.hpp): it decodes what
// lcm-gen encodes, and checks every length against the bytes and the plant's
// dimensions before anything is allocated. Issue 12: one 60-byte datagram
// with n_u = 2^31 - 1 used to make mpmd zero-fill 16 GB.
#include <gtest/gtest.h>

#include <lcm/lcm.h>

#include <chrono>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>

#include <unistd.h>
#include <vector>

#include "same_message.hpp"
#include "sample_messages.hpp"
#include "support/alloc_counter.hpp"
#include "transport/lcm_codec.hpp"
#include "transport/lcm_wire.hpp"
#include "transport/transport.hpp"
#include "wire_bytes.hpp"

namespace mpm::transport {
namespace {

using test::CraftedSample;

SampleLimits plant_limits(std::uint32_t n_u = 2, std::uint32_t n_y = 2) {
  SampleLimits l;
  l.n_u = n_u;
  l.n_y = n_y;
  return l;
}

std::vector<std::uint8_t> lcm_gen_encoded(const msg::Sample& in) {
  mpm_lcm::sample_t wire;
  lcm_codec::to_wire(in, wire);
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(wire.getEncodedSize()));
  EXPECT_EQ(wire.encode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
  return bytes;
}

WireError decode(const std::vector<std::uint8_t>& bytes, const SampleLimits& limits, msg::Sample& out) {
  return decode_lcm_sample(bytes.data(), bytes.size(), limits, out);
}

TEST(LcmWire, DecodesWhatLcmGenEncodes) {
  const msg::Sample in = test::full_sample();
  msg::Sample out;
  ASSERT_EQ(decode(lcm_gen_encoded(in), plant_limits(3, 2), out), WireError::kNone);
  test::expect_same_message(out, in);
}

TEST(LcmWire, HugeLengthInASmallDatagramAllocatesNothing) {
  CraftedSample c;
  c.n_u = std::numeric_limits<std::int32_t>::max();  // the 16 GB datagram of issue 12
  c.u.clear();
  const auto bytes = c.encode();
  ASSERT_LE(bytes.size(), 80u);
  msg::Sample out;
  ASSERT_EQ(decode(CraftedSample{}.encode(), plant_limits(), out), WireError::kNone);  // sized once
  {
    test::AllocationScope scope;
    EXPECT_EQ(decode(bytes, plant_limits(), out), WireError::kTruncated);
    EXPECT_EQ(scope.count(), 0);
  }
  EXPECT_LE(out.u.capacity(), 2u);
  // Without known dimensions (mpm listen) the cap and the bytes still bound it.
  SampleLimits any;
  EXPECT_NE(decode(bytes, any, out), WireError::kNone);
  EXPECT_LE(out.u.capacity(), 2u);
}

TEST(LcmWire, OffByOneLengthIsRefused) {
  CraftedSample c;
  c.n_u = 3;  // 2 values sent: the honest off-by-one that grew mpmd by 3 GB
  msg::Sample out;
  EXPECT_NE(decode(c.encode(), plant_limits(), out), WireError::kNone);
  EXPECT_NE(decode(c.encode(), SampleLimits{}, out), WireError::kNone);
  c.n_u = 1;  // one value too few: the rest shifts and nothing ends where it should
  EXPECT_NE(decode(c.encode(), plant_limits(), out), WireError::kNone);
  EXPECT_NE(decode(c.encode(), SampleLimits{}, out), WireError::kNone);
}

TEST(LcmWire, DimensionsOfThePlantAreEnforced) {
  msg::Sample out;
  CraftedSample c;
  c.n_u = 3;
  c.u = {1, 2, 3};
  EXPECT_EQ(decode(c.encode(), plant_limits(), out), WireError::kWrongInputs);
  c = CraftedSample{};
  c.n_y = 1;
  c.y = {1};
  EXPECT_EQ(decode(c.encode(), plant_limits(), out), WireError::kWrongOutputs);
  c = CraftedSample{};
  c.n_sim_y = 1;
  c.sim_y = {5};
  EXPECT_EQ(decode(c.encode(), plant_limits(), out), WireError::kWrongSimOutputs);
  c = CraftedSample{};
  SampleLimits few = plant_limits();
  few.max_extra = 2;
  c.extra_names = {"a", "b", "c"};
  c.extra_values = {1, 2, 3};
  EXPECT_EQ(decode(c.encode(), few, out), WireError::kTooManyExtras);
  c = CraftedSample{};
  c.controller_id = std::string(300, 'x');
  EXPECT_EQ(decode(c.encode(), plant_limits(), out), WireError::kStringTooLong);
}

TEST(LcmWire, BrokenStringsAndTrailingBytesAreRefused) {
  msg::Sample out;
  for (const std::int32_t n :
       {0, -1, std::numeric_limits<std::int32_t>::min(), std::numeric_limits<std::int32_t>::max()}) {
    test::WireBytes w;
    w.fingerprint().i32(n);
    EXPECT_NE(decode(w.bytes, plant_limits(), out), WireError::kNone) << n;
  }
  test::WireBytes no_nul;
  no_nul.fingerprint().i32(3);
  no_nul.bytes.insert(no_nul.bytes.end(), {'a', 'b', 'c'});
  EXPECT_EQ(decode(no_nul.bytes, plant_limits(), out), WireError::kBadLength);
  auto bytes = CraftedSample{}.encode();
  bytes.push_back(0);
  EXPECT_EQ(decode(bytes, plant_limits(), out), WireError::kTrailingBytes);
  bytes = CraftedSample{}.encode();
  bytes[0] ^= 1;
  EXPECT_EQ(decode(bytes, plant_limits(), out), WireError::kFingerprint);
  for (std::size_t n = 0; n < CraftedSample{}.encode().size(); ++n) {  // every truncation
    bytes = CraftedSample{}.encode();
    bytes.resize(n);
    EXPECT_NE(decode(bytes, plant_limits(), out), WireError::kNone) << n;
  }
}

// LCM 1.3's generated decoder skips a zero-length array, so a reused message
// kept a 10^6-long sim_y and every later valid sample looked malformed.
TEST(LcmWire, AnEmptyArrayClearsWhatTheLastSampleHad) {
  msg::Sample out;
  CraftedSample with_sim;
  with_sim.n_sim_y = 2;
  with_sim.sim_y = {7, 8};
  ASSERT_EQ(decode(with_sim.encode(), plant_limits(), out), WireError::kNone);
  ASSERT_EQ(out.sim_y.size(), 2u);
  ASSERT_EQ(decode(CraftedSample{}.encode(), plant_limits(), out), WireError::kNone);
  EXPECT_TRUE(out.sim_y.empty());
  EXPECT_TRUE(out.extra_names.empty());
}

TEST(LcmWire, SteadyStateDecodingAllocatesNothing) {
  CraftedSample c;
  c.n_sim_y = 2;
  c.sim_y = {1, 2};
  c.extra_names = {"feed_flow_with_a_name_longer_than_sso"};
  c.extra_values = {1.5};
  const auto bytes = c.encode();
  msg::Sample out;
  ASSERT_EQ(decode(bytes, plant_limits(), out), WireError::kNone);
  test::AllocationScope scope;
  for (int i = 0; i < 100; ++i) ASSERT_EQ(decode(bytes, plant_limits(), out), WireError::kNone);
  EXPECT_EQ(scope.count(), 0);
}

TEST(LcmWire, AlarmAndStatusChecksAcceptOursAndRefuseLies) {
  mpm_lcm::status_t status;
  lcm_codec::to_wire(test::full_status(), status);
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(status.getEncodedSize()));
  status.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  EXPECT_EQ(check_lcm_status(bytes.data(), bytes.size(), 256, 1000), WireError::kNone);
  // n_channels sits after the fingerprint, the id and 2*8+1+3*8+11*8 bytes.
  const std::size_t at = 8 + 4 + test::full_status().controller_id.size() + 1 + 2 * 8 + 1 + 3 * 8 + 11 * 8;
  bytes[at] = 0x7f;  // n_channels ~ 2^31
  EXPECT_EQ(check_lcm_status(bytes.data(), bytes.size(), 256, 1000), WireError::kTruncated);

  mpm_lcm::alarm_t alarm;
  lcm_codec::to_wire(test::full_alarm(), alarm);
  bytes.assign(static_cast<std::size_t>(alarm.getEncodedSize()), 0);
  alarm.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  EXPECT_EQ(check_lcm_alarm(bytes.data(), bytes.size(), 256), WireError::kNone);
  bytes[8 + 3] = 0;  // controller_id length 0: lcm-gen's decoder did assign(p, -1)
  bytes[8 + 2] = 0;
  bytes[8 + 1] = 0;
  bytes[8 + 0] = 0;
  EXPECT_NE(check_lcm_alarm(bytes.data(), bytes.size(), 256), WireError::kNone);
}

long rss_kb() {
  long pages = 0, rss = 0;
  std::FILE* f = std::fopen("/proc/self/statm", "r");
  if (f == nullptr) return 0;
  if (std::fscanf(f, "%ld %ld", &pages, &rss) != 2) rss = 0;
  std::fclose(f);
  return rss * 4;
}

// Through the real LCM adapter (udpm:// in the test's own network namespace):
// the hostile datagrams are counted as receive errors, memory does not grow,
// and a valid sample after them arrives.
TEST(LcmWire, TransportCountsHostileDatagramsAndKeepsReceiving) {
  Settings settings;
  settings.lcm.url = "udpm://239.255.76.69:" + std::to_string(31000 + ::getpid() % 500 * 3) + "?ttl=0";
  settings.sample_limits = plant_limits();
  std::string error;
  auto transport = create(settings, error);
  ASSERT_TRUE(transport) << error;
  std::vector<msg::Sample> received;
  ASSERT_TRUE(transport->subscribe_samples([&](const msg::Sample& s) { received.push_back(s); }));
  lcm_t* raw = lcm_create(settings.lcm.url.c_str());
  ASSERT_NE(raw, nullptr);
  const long before = rss_kb();
  CraftedSample hostile;
  hostile.n_u = std::numeric_limits<std::int32_t>::max();
  hostile.u.clear();
  CraftedSample off_by_one;
  off_by_one.n_u = 3;
  CraftedSample huge_sim;  // a long sim_y with the bytes to back it (one datagram)
  huge_sim.n_sim_y = 5000;
  huge_sim.sim_y.assign(5000, 1.0);
  CraftedSample valid;
  valid.seq = 2;
  for (const auto* c : {&hostile, &off_by_one, &huge_sim, &valid}) {
    const auto bytes = c->encode();
    ASSERT_EQ(
        lcm_publish(raw, settings.lcm.sample_channel.c_str(), bytes.data(), static_cast<unsigned>(bytes.size())), 0);
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (received.empty() && std::chrono::steady_clock::now() < deadline) {
    transport->handle(std::chrono::milliseconds(20));
  }
  lcm_destroy(raw);
  ASSERT_EQ(received.size(), 1u);
  EXPECT_EQ(received[0].seq, 2);
  EXPECT_TRUE(received[0].sim_y.empty());
  EXPECT_EQ(transport->receive_errors(), 3u);
  EXPECT_LT(rss_kb() - before, 100 * 1024);
}

}  // namespace
}  // namespace mpm::transport
