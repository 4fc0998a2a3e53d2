// Hand-made LCM datagrams for the wire tests and the fuzz seeds: big-endian
// writers for the fields of mpm_lcm.sample_t (lcm_wire.hpp has the layout),
// so a test can state any length it likes, honest or not.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include <mpm_lcm/sample_t.hpp>

namespace mpm::test {

class WireBytes {
 public:
  WireBytes& i64(std::int64_t v) {
    for (int s = 56; s >= 0; s -= 8) bytes.push_back(static_cast<std::uint8_t>(static_cast<std::uint64_t>(v) >> s));
    return *this;
  }
  WireBytes& i32(std::int32_t v) {
    for (int s = 24; s >= 0; s -= 8) bytes.push_back(static_cast<std::uint8_t>(static_cast<std::uint32_t>(v) >> s));
    return *this;
  }
  WireBytes& f64(double v) {
    std::int64_t bits = 0;
    std::memcpy(&bits, &v, sizeof v);
    return i64(bits);
  }
  WireBytes& str(const std::string& s) {
    i32(static_cast<std::int32_t>(s.size() + 1));
    bytes.insert(bytes.end(), s.begin(), s.end());
    bytes.push_back(0);
    return *this;
  }
  WireBytes& doubles(std::int32_t n_claimed, const std::vector<double>& values) {
    i32(n_claimed);
    for (double v : values) f64(v);
    return *this;
  }
  WireBytes& fingerprint() { return i64(mpm_lcm::sample_t::getHash()); }

  std::vector<std::uint8_t> bytes;
};

// A sample_t as lcm-gen would encode it, with each length stated separately
// from the values that follow it.
struct CraftedSample {
  std::string controller_id = "column-7";
  std::int64_t session_id = 77;
  std::int64_t seq = 1;
  std::int64_t utime = 0;
  std::int32_t n_u = 2;
  std::vector<double> u = {1.0, 2.0};
  std::int32_t n_y = 2;
  std::vector<double> y = {3.0, 4.0};
  std::int32_t n_sim_y = 0;
  std::vector<double> sim_y;
  std::vector<std::string> extra_names;
  std::vector<double> extra_values;

  std::vector<std::uint8_t> encode() const {
    WireBytes w;
    w.fingerprint().str(controller_id).i64(session_id).i64(seq).i64(utime);
    w.doubles(n_u, u).doubles(n_y, y).doubles(n_sim_y, sim_y);
    w.i32(static_cast<std::int32_t>(extra_names.size()));
    for (const auto& name : extra_names) w.str(name);
    for (double v : extra_values) w.f64(v);
    return w.bytes;
  }
};

}  // namespace mpm::test
