// Any bytes as an lcm-logger file given to `mpm diagnose --data`
// (daemon/lcm_log_reader.hpp): a recording whose rows hold only finite
// numbers or NaN, or a ConfigError that names the file and holds no control
// character (nothing from the file is echoed raw). liblcm's reader sees a
// frame only after its lengths were checked against the file, so a lying
// length must never reach its allocation.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

#include "daemon/lcm_log_reader.hpp"
#include "tests/fuzz/fuzz_support.hpp"

namespace {
// Made at first use, once per process.
const mpm::PlantModel& plant() { static const mpm::PlantModel p = mpm::fuzz::small_plant("[y1, y2]"); return p; }
const std::string& scratch() { static const std::string p = mpm::fuzz::scratch_path("lcm_log", ".lcmlog"); return p; }
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::FILE* f = std::fopen(scratch().c_str(), "wb");
  if (!f) return 0;
  std::fwrite(data, 1, size, f);
  std::fclose(f);
  try {
    const mpm::config::Recording rec = mpm::transport::load_lcm_log(scratch(), plant());
    if (rec.names.size() < 5 || static_cast<std::size_t>(rec.data.cols()) != rec.names.size()) __builtin_trap();
    for (Eigen::Index k = 0; k < rec.data.size(); ++k)
      if (std::isinf(rec.data.data()[k])) __builtin_trap();
  } catch (const mpm::config::ConfigError& e) {
    const std::string what = e.what();
    if (what.rfind(scratch() + ":", 0) != 0) __builtin_trap();
    for (const char c : what)
      if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) __builtin_trap();
  }
  return 0;
}
