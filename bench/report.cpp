// Machine description and the two output forms of `mpm bench`.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "bench/figures.hpp"
#include "config/json_text.hpp"

namespace mpm::bench {
namespace {

using config::json_string;
std::string number(double v) { return config::json_number(v, 6); }

}  // namespace

std::string machine_description() {
  std::ifstream in("/proc/cpuinfo");
  std::string line, model = "unknown CPU";
  int cpus = 0;
  while (std::getline(in, line)) {
    if (line.rfind("processor", 0) == 0) ++cpus;
    if (line.rfind("model name", 0) == 0 && model == "unknown CPU") {
      const auto colon = line.find(':');
      if (colon != std::string::npos) model = line.substr(line.find_first_not_of(" \t", colon + 1));
    }
  }
  return model + ", " + std::to_string(cpus) + " logical CPUs";
}

std::string to_json(const std::string& machine, const std::vector<Figure>& figures) {
  std::ostringstream out;
  out << "{\"machine\": " << json_string(machine) << ", \"figures\": [";
  for (std::size_t i = 0; i < figures.size(); ++i) {
    const Figure& f = figures[i];
    out << (i ? ",\n  " : "\n  ") << "{\"name\": " << json_string(f.name)
        << ", \"value\": " << (f.value ? number(*f.value) : "null") << ", \"unit\": " << json_string(f.unit)
        << ", \"note\": " << json_string(f.note) << "}";
  }
  out << "\n]}\n";
  return out.str();
}

std::string to_table(const std::string& machine, const std::vector<Figure>& figures) {
  std::ostringstream out;
  out << "machine: " << machine << "\n\n";
  char buf[128];
  std::snprintf(buf, sizeof buf, "%-26s %14s %-10s %s\n", "figure", "value", "unit", "how / note");
  out << buf;
  for (const Figure& f : figures) {
    const std::string value = f.value ? number(*f.value) : "n/a";
    std::snprintf(buf, sizeof buf, "%-26s %14s %-10s ", f.name.c_str(), value.c_str(), f.unit.c_str());
    out << buf << f.note << "\n";
  }
  return out.str();
}

}  // namespace mpm::bench
