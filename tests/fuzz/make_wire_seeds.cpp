// Writes the seed corpora of the wire fuzz targets (committed under
// tests/fuzz/corpus/lcm_sample and dds_sample; re-run after a message
// change):  make_wire_seeds <corpus dir>
// LCM seeds: encodings by lcm-gen's own encoder (samples of several shapes,
// an alarm, a status) and hand-made edge cases (lying lengths, a string
// without its NUL). DDS seeds: bodies serialised by Cyclone (XCDR1 and XCDR2)
// behind the target's one-byte mode prefix, and one with a lying length.
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include <dds/ddsi/ddsi_cdrstream.h>

#include "transport/dds_codec.hpp"
#include "transport/lcm_codec.hpp"
#include "transport/sample_messages.hpp"
#include "transport/wire_bytes.hpp"

namespace {

void write(const std::string& path, const std::vector<std::uint8_t>& bytes) {
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (f == nullptr) {
    std::perror(path.c_str());
    return;
  }
  std::fwrite(bytes.data(), 1, bytes.size(), f);
  std::fclose(f);
}

template <typename Wire, typename Plain>
std::vector<std::uint8_t> lcm_encoded(const Plain& plain) {
  Wire wire;
  mpm::transport::lcm_codec::to_wire(plain, wire);
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(wire.getEncodedSize()));
  wire.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

std::vector<std::uint8_t> dds_encoded(const mpm::msg::Sample& plain, std::uint8_t mode) {
  mpm_dds_Sample wire{};
  mpm::transport::dds_codec::Scratch scratch;
  mpm::transport::dds_codec::to_wire(plain, wire, scratch);
  dds_ostream_t os;
  dds_ostream_init(&os, 0, (mode & 2) ? 2u : 1u);
  dds_stream_write(&os, reinterpret_cast<const char*>(&wire), mpm_dds_Sample_desc.m_ops);
  std::vector<std::uint8_t> bytes{mode};
  bytes.insert(bytes.end(), os.m_buffer, os.m_buffer + os.m_index);
  dds_ostream_fini(&os);
  return bytes;
}

mpm::msg::Sample two_by_two() {
  mpm::msg::Sample s;
  s.controller_id = "wb";
  s.session_id = 42;
  s.seq = 1;
  s.u = {15.0, 12.0};
  s.y = {90.0, 5.0};
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_wire_seeds CORPUS_DIR (writes lcm_sample/ and dds_sample/ in it)\n");
    return 2;
  }
  const std::string lcm = std::string(argv[1]) + "/lcm_sample/";
  const std::string dds = std::string(argv[1]) + "/dds_sample/";
  using mpm::test::CraftedSample;

  mpm::msg::Sample plain = two_by_two();
  write(lcm + "valid_2x2", lcm_encoded<mpm_lcm::sample_t>(plain));
  mpm::msg::Sample with_sim = plain;
  with_sim.sim_y = {89.5, 5.25};
  with_sim.extra_names = {"feed_flow", "r_y1"};
  with_sim.extra_values = {2.5, 90.0};
  write(lcm + "valid_2x2_sim_extra", lcm_encoded<mpm_lcm::sample_t>(with_sim));
  write(lcm + "valid_3x2", lcm_encoded<mpm_lcm::sample_t>(mpm::test::full_sample()));
  write(lcm + "alarm", lcm_encoded<mpm_lcm::alarm_t>(mpm::test::full_alarm()));
  write(lcm + "status", lcm_encoded<mpm_lcm::status_t>(mpm::test::full_status()));
  CraftedSample c;
  c.n_u = std::numeric_limits<std::int32_t>::max();
  c.u.clear();
  write(lcm + "n_u_int32_max", c.encode());
  c = CraftedSample{};
  c.n_u = 3;
  write(lcm + "n_u_off_by_one", c.encode());
  c = CraftedSample{};
  c.seq = std::numeric_limits<std::int64_t>::max();
  c.session_id = std::numeric_limits<std::int64_t>::min();
  write(lcm + "seq_extremes", c.encode());
  mpm::test::WireBytes w;
  w.fingerprint().i32(0);
  write(lcm + "string_length_zero", w.bytes);
  w = mpm::test::WireBytes{};
  w.fingerprint().i32(4);
  w.bytes.insert(w.bytes.end(), {'a', 'b', 'c', 'd'});
  write(lcm + "string_without_nul", w.bytes);

  for (const std::uint8_t mode : {std::uint8_t{0}, std::uint8_t{2}}) {
    const std::string suffix = mode ? "_xcdr2" : "_xcdr1";
    write(dds + "valid_2x2" + suffix, dds_encoded(plain, mode));
    write(dds + "valid_2x2_sim_extra" + suffix, dds_encoded(with_sim, mode));
    write(dds + "valid_3x2" + suffix, dds_encoded(mpm::test::full_sample(), mode));
  }
  // The length of u (after the id and three int64, XCDR1: 4-aligned) made huge.
  std::vector<std::uint8_t> lying = dds_encoded(plain, 0);
  const std::size_t id_bytes = 4 + plain.controller_id.size() + 1;
  std::size_t at = 1 + ((id_bytes + 7) / 8) * 8 + 3 * 8;
  if (at + 4 <= lying.size()) std::memset(&lying[at], 0x7f, 4);
  write(dds + "u_length_huge", lying);
  return 0;
}
