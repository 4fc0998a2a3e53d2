// libFuzzer target: arbitrary bytes as a received LCM datagram on the sample,
// alarm and status channels (transport/lcm_wire.hpp).
//
// Checked besides "no crash, no leak, no UB, no huge allocation":
//   * our sample decoder never grows the reused message beyond the limits;
//   * what it accepts, lcm-gen's decoder decodes too, to the same fields and
//     the same number of bytes (a differential check of our reading of the
//     layout), and it is only ever run on bytes ours accepted;
//   * the same for the alarm and status walks before their generated decoders.
// Seeds: tests/fuzz/corpus/lcm_sample (valid encodings and edge cases).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "transport/lcm_codec.hpp"
#include "transport/lcm_wire.hpp"

namespace {

using mpm::transport::SampleLimits;
using mpm::transport::WireError;

void require(bool ok) {
  if (!ok) std::abort();  // libFuzzer reports it as a crash with the input
}

bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0);
}

// `out` is reused across inputs, as the transport reuses its message.
void sample(const std::uint8_t* data, std::size_t size, const SampleLimits& limits, mpm::msg::Sample& out) {
  const WireError error = mpm::transport::decode_lcm_sample(data, size, limits, out);
  const std::size_t cap = limits.n_u ? limits.n_u : limits.max_channels;
  require(out.u.size() <= cap && out.controller_id.size() <= limits.max_string &&
          out.extra_names.size() <= limits.max_extra);
  if (error != WireError::kNone) return;
  mpm_lcm::sample_t wire;
  require(wire.decode(data, 0, static_cast<int>(size)) == static_cast<int>(size));
  require(wire.controller_id == out.controller_id && wire.seq == out.seq && wire.session_id == out.session_id &&
          wire.utime == out.utime && same_bits(wire.u, out.u) && same_bits(wire.y, out.y) &&
          same_bits(wire.sim_y, out.sim_y) && wire.extra_names == out.extra_names &&
          same_bits(wire.extra_values, out.extra_values));
}

template <typename Wire>
void generated_after_check(WireError checked, const std::uint8_t* data, std::size_t size) {
  if (checked != WireError::kNone) return;
  Wire wire;
  require(wire.decode(data, 0, static_cast<int>(size)) == static_cast<int>(size));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > (1u << 20)) return 0;  // LCM's datagrams; larger inputs only slow the search
  SampleLimits plant;               // a 2 x 2 plant, as mpmd runs
  plant.n_u = 2;
  plant.n_y = 2;
  static mpm::msg::Sample for_plant, for_any;
  sample(data, size, plant, for_plant);
  sample(data, size, SampleLimits{}, for_any);  // no plant known (mpm listen)
  generated_after_check<mpm_lcm::alarm_t>(mpm::transport::check_lcm_alarm(data, size, 256), data, size);
  generated_after_check<mpm_lcm::status_t>(mpm::transport::check_lcm_status(data, size, 256, 65536), data, size);
  return 0;
}
