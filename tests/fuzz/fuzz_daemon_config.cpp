// Any bytes as mpmd.yaml: a DaemonConfig or a ConfigError naming the source.
#include <cstddef>
#include <cstdint>
#include <string>

#include "config/daemon_config.hpp"
#include "config/plant_loader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    // No base directory: a relative plant path is looked up from the working
    // directory, where it is (almost always) missing, a located error.
    const auto c = mpm::config::parse_daemon_config(text, "fuzz.yaml", "");
    if (c.queue_capacity < 2 || c.status_period < 0.01) __builtin_trap();
  } catch (const mpm::config::ConfigError& e) {
    if (std::string(e.what()).rfind("fuzz.yaml:", 0) != 0) __builtin_trap();
  }
  return 0;
}
