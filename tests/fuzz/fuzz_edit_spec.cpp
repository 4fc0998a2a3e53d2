// Any bytes as `--edit` specs, one per line, applied to a 2x2 plant and
// built: a plant, or std::invalid_argument. Anything else is a crash.
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "config/plant_loader.hpp"
#include "sim/edit_spec.hpp"
#include "sim/plant_builder.hpp"

namespace {
const mpm::PlantModel& model() {
  static const mpm::PlantModel p = mpm::config::parse_plant(
      "plant: f\nsample_time: 1\ninputs: [u1, u2]\noutputs: [y1, y2]\nmodel:\n"
      "  - {output: y1, input: u1, num: [0.5], den: [1, -0.5], delay: 1}\n"
      "  - {output: y2, input: u2, num: [0.2, 0.1], den: [1, -0.9], delay: 2}\n",
      "plant.yaml");
  return p;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string_view text(reinterpret_cast<const char*>(data), size);
  std::vector<mpm::sim::EditSpec> specs;
  while (!text.empty() && specs.size() < 16) {
    const auto end = text.find('\n');
    const std::string_view line = text.substr(0, end);
    text = end == std::string_view::npos ? std::string_view{} : text.substr(end + 1);
    try {
      specs.push_back(mpm::sim::parse_edit(line, model().inputs, model().outputs));
    } catch (const std::invalid_argument&) {
    }
  }
  try {
    mpm::sim::PlantSpec spec;
    mpm::sim::apply_edits(specs, spec);
    (void)mpm::sim::build_plant(model(), spec);
    (void)mpm::sim::describe(specs);
  } catch (const std::invalid_argument&) {
  }
  return 0;
}
