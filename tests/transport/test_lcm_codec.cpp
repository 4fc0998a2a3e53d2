// The LCM wire types: what is encoded decodes to the same plain message, the
// array lengths are always set, and inconsistent wire messages are refused.
#include <gtest/gtest.h>

#include <vector>

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

TEST(LcmCodec, SampleRoundTrip) {
  const msg::Sample in = test::full_sample();
  const msg::Sample out = round_trip<mpm_lcm::sample_t>(in);
  EXPECT_EQ(out.controller_id, in.controller_id);
  EXPECT_EQ(out.session_id, in.session_id);
  EXPECT_EQ(out.seq, in.seq);
  EXPECT_EQ(out.utime, in.utime);
  EXPECT_EQ(out.u, in.u);
  EXPECT_EQ(out.y, in.y);
  EXPECT_EQ(out.sim_y, in.sim_y);
  EXPECT_EQ(out.extra_names, in.extra_names);
  EXPECT_EQ(out.extra_values, in.extra_values);
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
  const msg::Sample out = round_trip<mpm_lcm::sample_t>(in);
  EXPECT_TRUE(out.sim_y.empty());
  EXPECT_TRUE(out.extra_names.empty());
  EXPECT_EQ(out.u, in.u);
}

TEST(LcmCodec, AlarmRoundTrip) {
  const msg::Alarm in = test::full_alarm();
  const msg::Alarm out = round_trip<mpm_lcm::alarm_t>(in);
  EXPECT_EQ(out.controller_id, in.controller_id);
  EXPECT_EQ(out.utime, in.utime);
  EXPECT_EQ(out.sample_sequence, in.sample_sequence);
  EXPECT_EQ(out.output, in.output);
  EXPECT_EQ(out.input, in.input);
  EXPECT_EQ(out.output_index, in.output_index);
  EXPECT_EQ(out.input_index, in.input_index);
  EXPECT_EQ(out.raised, in.raised);
  EXPECT_EQ(out.f, in.f);
  EXPECT_EQ(out.p_value, in.p_value);
  EXPECT_EQ(out.gamma, in.gamma);
  EXPECT_EQ(out.physics, in.physics);
  EXPECT_EQ(out.text, in.text);
}

TEST(LcmCodec, StatusRoundTrip) {
  const msg::Status in = test::full_status();
  const msg::Status out = round_trip<mpm_lcm::status_t>(in);
  EXPECT_EQ(out.controller_id, in.controller_id);
  EXPECT_EQ(out.uptime_ms, in.uptime_ms);
  EXPECT_EQ(out.ready, in.ready);
  EXPECT_EQ(out.effective_samples, in.effective_samples);
  EXPECT_EQ(out.raise_threshold, in.raise_threshold);
  EXPECT_EQ(out.clear_threshold, in.clear_threshold);
  EXPECT_EQ(out.samples_seen, in.samples_seen);
  EXPECT_EQ(out.samples_used, in.samples_used);
  EXPECT_EQ(out.dropped, in.dropped);
  EXPECT_EQ(out.gaps, in.gaps);
  EXPECT_EQ(out.missing, in.missing);
  EXPECT_EQ(out.duplicates, in.duplicates);
  EXPECT_EQ(out.out_of_order, in.out_of_order);
  EXPECT_EQ(out.restarts, in.restarts);
  EXPECT_EQ(out.malformed, in.malformed);
  EXPECT_EQ(out.nan_samples, in.nan_samples);
  EXPECT_EQ(out.alarms_raised, in.alarms_raised);
  ASSERT_EQ(out.channels.size(), 2u);
  EXPECT_EQ(out.channels[1].output, "y2");
  EXPECT_EQ(out.channels[1].input, "u1");
  EXPECT_EQ(out.channels[1].lr, 60.0);
  EXPECT_TRUE(out.channels[1].alarm);
  EXPECT_TRUE(test::same_double(out.channels[1].gamma, in.channels[1].gamma));
  ASSERT_EQ(out.loops.size(), 2u);
  EXPECT_EQ(out.loops[1].residual_variance, 5.3);
  EXPECT_TRUE(out.loops[1].alarm);
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
