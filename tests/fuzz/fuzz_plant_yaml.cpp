// Any bytes as a plant file: either a PlantModel that keeps the loader's
// promises or a ConfigError naming the source. Any other exception (a bare
// std::invalid_argument from core/, bad_alloc) escapes and is a crash.
#include <cstddef>
#include <cstdint>
#include <string>

#include "config/plant_loader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const mpm::PlantModel plant = mpm::config::parse_plant(text, "fuzz.yaml");
    const mpm::config::Limits limits;
    if (plant.inputs.empty() || plant.inputs.size() > limits.max_inputs) __builtin_trap();
    if (plant.outputs.empty() || plant.outputs.size() > limits.max_outputs) __builtin_trap();
    for (const auto& ch : plant.channels) {
      if (ch.output >= plant.outputs.size() || ch.input >= plant.inputs.size()) __builtin_trap();
      if (ch.tf.delay < 0 || ch.tf.delay > limits.max_delay_samples) __builtin_trap();
    }
  } catch (const mpm::config::ConfigError& e) {
    if (std::string(e.what()).rfind("fuzz.yaml:", 0) != 0) __builtin_trap();  // unlocated
  }
  return 0;
}
