// DDS samples are checked against the plant's limits before they are copied
// into the reused message (transport/dds_codec.hpp): the same rules as the
// LCM decoder, and a refused sample leaves the message as it was.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "transport/dds_codec.hpp"

namespace mpm::transport {
namespace {

struct DdsSample {
  DdsSample() {
    wire.controller_id = id.data();
    set(wire.u, u);
    set(wire.y, y);
    set(wire.sim_y, sim_y);
  }
  static void set(dds_sequence_double& seq, std::vector<double>& v) {
    seq._length = seq._maximum = static_cast<std::uint32_t>(v.size());
    seq._buffer = v.empty() ? nullptr : v.data();
  }
  std::string id = "wb";
  std::vector<double> u{1, 2}, y{3, 4}, sim_y;
  std::vector<mpm_dds_NamedValue> extra;
  mpm_dds_Sample wire{};
};

SampleLimits two_by_two() {
  SampleLimits l;
  l.n_u = 2;
  l.n_y = 2;
  return l;
}

TEST(DdsLimits, AcceptsWhatFitsAndCopiesIt) {
  DdsSample s;
  msg::Sample out;
  ASSERT_EQ(dds_codec::from_wire(s.wire, two_by_two(), out), WireError::kNone);
  EXPECT_EQ(out.u, s.u);
  EXPECT_EQ(out.controller_id, "wb");
}

TEST(DdsLimits, RefusesWhatDoesNotFitAndLeavesTheMessageUnchanged) {
  msg::Sample out;
  {
    DdsSample good;
    ASSERT_EQ(dds_codec::from_wire(good.wire, two_by_two(), out), WireError::kNone);
  }
  const msg::Sample before = out;
  auto refused = [&](DdsSample& s, WireError expected, const SampleLimits& limits = two_by_two()) {
    EXPECT_EQ(dds_codec::from_wire(s.wire, limits, out), expected);
    EXPECT_EQ(out.u, before.u);
    EXPECT_EQ(out.y, before.y);
    EXPECT_EQ(out.controller_id, before.controller_id);
  };
  DdsSample three_inputs;
  three_inputs.u = {1, 2, 3};
  DdsSample::set(three_inputs.wire.u, three_inputs.u);
  refused(three_inputs, WireError::kWrongInputs);
  DdsSample one_output;
  one_output.y = {1};
  DdsSample::set(one_output.wire.y, one_output.y);
  refused(one_output, WireError::kWrongOutputs);
  DdsSample odd_sim;
  odd_sim.sim_y = {1};
  DdsSample::set(odd_sim.wire.sim_y, odd_sim.sim_y);
  refused(odd_sim, WireError::kWrongSimOutputs);
  DdsSample long_id;
  long_id.id.assign(300, 'x');
  long_id.wire.controller_id = long_id.id.data();
  refused(long_id, WireError::kStringTooLong);
  DdsSample many;
  std::string name = "x";
  many.extra.assign(300, mpm_dds_NamedValue{name.data(), 1.0});
  many.wire.extra._length = many.wire.extra._maximum = 300;
  many.wire.extra._buffer = many.extra.data();
  refused(many, WireError::kTooManyExtras);
  DdsSample no_buffer;
  no_buffer.wire.sim_y._length = 2;
  no_buffer.wire.sim_y._buffer = nullptr;
  refused(no_buffer, WireError::kBadLength);
  // Without a plant (mpm listen) the general cap still bounds u and y.
  DdsSample huge;
  huge.u.assign(5000, 0.0);
  DdsSample::set(huge.wire.u, huge.u);
  refused(huge, WireError::kWrongInputs, SampleLimits{});
}

}  // namespace
}  // namespace mpm::transport
