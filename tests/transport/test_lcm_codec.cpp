// The LCM wire types: what is encoded decodes to the same plain message, the
// array lengths are always set, and inconsistent wire messages are refused.
#include <gtest/gtest.h>

#include <vector>

#include "same_message.hpp"
#include "sample_messages.hpp"
#include "transport/lcm_codec.hpp"

namespace mpm::transport {
namespace {

template <typename Wire, typename Plain>
Plain round_trip(const Plain& in) {
  Wire wire;
  lcm_codec::to_wire(in, wire);
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(wire.getEncodedSize()));
  EXPECT_EQ(wire.encode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
  Wire decoded;
  EXPECT_EQ(decoded.decode(bytes.data(), 0, static_cast<int>(bytes.size())), static_cast<int>(bytes.size()));
  Plain out;
  EXPECT_TRUE(lcm_codec::from_wire(decoded, out));
  return out;
}

TEST(LcmCodec, EveryKindRoundTripsWithEveryField) {
  test::expect_same_message(round_trip<mpm_lcm::sample_t>(test::full_sample()), test::full_sample());
  test::expect_same_message(round_trip<mpm_lcm::alarm_t>(test::full_alarm()), test::full_alarm());
  test::expect_same_message(round_trip<mpm_lcm::status_t>(test::full_status()), test::full_status());
}

TEST(LcmCodec, LengthFieldsAreSet) {
  mpm_lcm::sample_t wire;
  lcm_codec::to_wire(test::full_sample(), wire);
  EXPECT_EQ(wire.n_u, 3);
  EXPECT_EQ(wire.n_y, 2);
  EXPECT_EQ(wire.n_sim_y, 2);
  EXPECT_EQ(wire.n_extra, 2);
  mpm_lcm::status_t status;
  lcm_codec::to_wire(test::full_status(), status);
  EXPECT_EQ(status.n_channels, 2);
  EXPECT_EQ(status.n_loops, 2);
}

TEST(LcmCodec, SampleWithoutOptionalPartsRoundTrips) {
  msg::Sample in = test::full_sample();
  in.sim_y.clear();
  in.extra_names.clear();
  in.extra_values.clear();
  test::expect_same_message(round_trip<mpm_lcm::sample_t>(in), in);
}

TEST(LcmCodec, InconsistentLengthsAreRefused) {
  mpm_lcm::sample_t wire;
  lcm_codec::to_wire(test::full_sample(), wire);
  wire.n_u = 2;  // says 2, carries 3
  msg::Sample out;
  EXPECT_FALSE(lcm_codec::from_wire(wire, out));
}

}  // namespace
}  // namespace mpm::transport
