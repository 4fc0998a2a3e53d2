// What the fuzz targets that need a plant or a file share.
#pragma once

#include <unistd.h>

#include <string>

#include "config/plant_loader.hpp"

namespace mpm::fuzz {

// Inputs u1, u2 and the outputs `outputs` (a YAML list starting with y1),
// one channel y1 <- u1: small enough that every input binds quickly.
inline PlantModel small_plant(const std::string& outputs) {
  return config::parse_plant("plant: f\nsample_time: 1\ninputs: [u1, u2]\noutputs: " + outputs +
                                 "\nmodel:\n  - {output: y1, input: u1, num: [0.5], den: [1, -0.5], delay: 1}\n",
                             "plant.yaml");
}

// A scratch file of this process (fuzzers run in parallel under ctest).
inline std::string scratch_path(const std::string& tag, const std::string& extension) {
  return "/tmp/mpm_fuzz_" + tag + "_" + std::to_string(::getpid()) + extension;
}

}  // namespace mpm::fuzz
