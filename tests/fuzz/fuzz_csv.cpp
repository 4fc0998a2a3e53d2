// Any bytes as a CSV recording: a Recording whose matrix matches its header,
// or a ConfigError naming the source; then bound to a small plant. The same
// bytes read by the streaming reader (CsvRowReader, from a scratch file)
// must give the same values or the same error.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "config/csv_stream.hpp"
#include "config/plant_loader.hpp"
#include "tests/fuzz/fuzz_support.hpp"

namespace {
// Made at first use, once per process.
const mpm::PlantModel& plant() { static const mpm::PlantModel p = mpm::fuzz::small_plant("[y1]"); return p; }
const std::string& scratch() { static const std::string path = mpm::fuzz::scratch_path("csv", ".csv"); return path; }

bool same(double a, double b) { return (std::isnan(a) && std::isnan(b)) || a == b; }
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  mpm::config::Recording rec;
  std::string error;
  try {
    rec = mpm::config::parse_recording(text, scratch());
    if (rec.names.empty() || static_cast<std::size_t>(rec.data.cols()) != rec.names.size())
      __builtin_trap();
    for (Eigen::Index k = 0; k < rec.data.size(); ++k)
      if (std::isinf(rec.data.data()[k])) __builtin_trap();  // only finite or NaN
    try {
      (void)mpm::config::bind(plant(), rec);
    } catch (const mpm::config::ConfigError& e) {
      if (std::string(e.what()).rfind(scratch(), 0) != 0) __builtin_trap();
    }
  } catch (const mpm::config::ConfigError& e) {
    error = e.what();
    if (error.rfind(scratch() + ":", 0) != 0) __builtin_trap();  // unlocated
  }

  std::FILE* f = std::fopen(scratch().c_str(), "wb");
  if (!f) return 0;
  std::fwrite(text.data(), 1, text.size(), f);
  std::fclose(f);
  std::string stream_error;
  std::vector<double> values, row;
  try {
    mpm::config::CsvRowReader reader(scratch());
    if (error.empty() && reader.names() != rec.names) __builtin_trap();
    while (reader.next(row)) values.insert(values.end(), row.begin(), row.end());
  } catch (const mpm::config::ConfigError& e) {
    stream_error = e.what();
  }
  if (stream_error != error) __builtin_trap();
  if (error.empty()) {
    if (values.size() != static_cast<std::size_t>(rec.data.size())) __builtin_trap();
    std::size_t k = 0;
    for (Eigen::Index r = 0; r < rec.data.rows(); ++r)
      for (Eigen::Index c = 0; c < rec.data.cols(); ++c)
        if (!same(rec.data(r, c), values[k++])) __builtin_trap();
  }
  return 0;
}
