// Any bytes as a CSV recording: a Recording whose matrix matches its header,
// or a ConfigError naming the source; then bound to a small plant.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "config/plant_loader.hpp"

namespace {
const mpm::PlantModel& plant() {
  static const mpm::PlantModel p = mpm::config::parse_plant(
      "plant: f\nsample_time: 1\ninputs: [u1, u2]\noutputs: [y1]\nmodel:\n"
      "  - {output: y1, input: u1, num: [0.5], den: [1, -0.5], delay: 1}\n",
      "plant.yaml");
  return p;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const auto rec = mpm::config::parse_recording(text, "fuzz.csv");
    if (rec.names.empty() || static_cast<std::size_t>(rec.data.cols()) != rec.names.size())
      __builtin_trap();
    for (Eigen::Index k = 0; k < rec.data.size(); ++k)
      if (std::isinf(rec.data.data()[k])) __builtin_trap();  // only finite or NaN
    (void)mpm::config::bind(plant(), rec);
  } catch (const mpm::config::ConfigError& e) {
    if (std::string(e.what()).rfind("fuzz.csv:", 0) != 0) __builtin_trap();
  }
  return 0;
}
