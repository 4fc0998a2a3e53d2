// bind(): matches a recording's columns to a plant's inputs and outputs.
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "config/plant_loader.hpp"

namespace mpm::config {
namespace {

std::string list_columns(const Recording& rec) {
  std::string out;
  for (const auto& n : rec.names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

std::size_t require_column(const Recording& rec, const std::string& name, const std::string& role) {
  const auto index = rec.find(name);
  if (!index)
    throw ConfigError(rec.source + ": missing column '" + name + "' (" + role +
                      "); the recording has: " + list_columns(rec));
  return *index;
}

std::string number(double x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.10g", x);
  return text;
}

// t must be present on every row and advance by sample_time each row.
void check_time(const Recording& rec, std::size_t time_col, double ts) {
  const auto t = rec.data.col(static_cast<Eigen::Index>(time_col));
  // Line numbers in messages: the header is line 1, row k is line k + 2.
  auto fail = [&](Eigen::Index row, const std::string& what) {
    throw ConfigError(rec.source + ":" + std::to_string(row + 2) + ": column 't': " + what);
  };
  for (Eigen::Index k = 0; k < t.size(); ++k) {
    if (std::isnan(t[k])) fail(k, "time is missing");
    if (k == 0) continue;
    const double step = t[k] - t[k - 1];
    // Relative tolerance on the step, plus the rounding of t itself (large
    // absolute times such as Unix seconds carry a few ulps of noise).
    const double tolerance =
        1e-6 * ts + 4 * std::numeric_limits<double>::epsilon() * std::abs(t[k]);
    if (std::abs(step - ts) > tolerance)
      fail(k, "time goes from " + number(t[k - 1]) + " to " + number(t[k]) +
                  ", expected a step of sample_time = " + number(ts));
  }
}

}  // namespace

BoundRecording bind(const PlantModel& plant, const Recording& rec) {
  BoundRecording b;
  b.time = require_column(rec, "t", "time in seconds");
  std::vector<bool> used(rec.names.size(), false);
  used[b.time] = true;
  for (const auto& name : plant.inputs) {
    b.inputs.push_back(require_column(rec, name, "plant input"));
    used[b.inputs.back()] = true;
  }
  for (const auto& name : plant.outputs) {
    b.outputs.push_back(require_column(rec, name, "plant output"));
    used[b.outputs.back()] = true;
    b.sim.push_back(rec.find("sim_" + name));
    b.setpoints.push_back(rec.find("r_" + name));
    if (b.sim.back()) used[*b.sim.back()] = true;
    if (b.setpoints.back()) used[*b.setpoints.back()] = true;
  }
  for (std::size_t c = 0; c < used.size(); ++c)
    if (!used[c]) b.extra.push_back(c);
  check_time(rec, b.time, plant.sample_time);
  return b;
}

}  // namespace mpm::config
