// `mpm monitor` over a recording read as a stream (config/csv_stream.hpp):
// memory independent of the record's length. Two passes over the file: the
// first checks the time column and finds what compute_residuals needs from
// the whole record (u0 by the front end's rule, the sample count that caps
// the settle time), the second computes each residual by the front end
// (core/monitor_front_end.hpp) and updates the monitor at once. The same residuals and, with the monitor updated on
// one thread, the same statistics as compute_residuals + monitor_record,
// which are bit for bit those of its parallel replay (offline.hpp).
#pragma once

#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "config/row_source.hpp"
#include "config/plant_loader.hpp"
#include "core/monitor_front_end.hpp"
#include "daemon/offline.hpp"

namespace mpm {

struct StreamedRecord {
  GrangerMonitor monitor;
  std::size_t samples = 0;
  std::size_t transient = 0;
  std::string notes;  // what the reader skipped (an LCM log), for the user
};

// Opens the recording again for each pass (daemon/data_input.hpp open_data).
using RowSourceOpener = std::function<std::unique_ptr<config::RowSource>()>;
// Called for every row once the front end knows u0, before the monitor's
// update: absolute inputs, residual and where the row stands (the rows mpmd
// keeps in its diagnosis ring: the settling ones with a NaN residual).
using RowCallback = std::function<void(const double* u, const double* residual, ResidualFrontEnd::Stage)>;

inline StreamedRecord monitor_csv_stream(const PlantModel& plant, const RowSourceOpener& open,
                                         const MonitorSettings& settings, bool plain_lags,
                                         const PartSampleCallback& on_sample, int settle_samples = -1,
                                         const RowCallback& on_row = {}) {
  // Column indices and names as bind() gives them (its time check runs on
  // the rows below, with the same message).
  config::Recording header;
  std::vector<double> row;
  config::BoundRecording bound;
  std::string path;
  {
    const auto reader = open();
    path = reader->source();
    header.source = path;
    header.names = reader->names();
    header.data.resize(0, static_cast<Eigen::Index>(header.names.size()));
    bound = config::bind(plant, header);
  }
  const std::size_t m = plant.n_inputs(), p = plant.n_outputs();
  const double ts = plant.sample_time;
  InputOrigin origin(plant);
  std::vector<double> u(m), y(p), sim_y(p), d(p);
  std::size_t n = 0;
  {
    const auto reader = open();
    double last_t = 0.0;
    while (reader->next(row)) {
      const double t = row[bound.time];
      auto fail = [&](const std::string& what) {
        throw config::ConfigError(path + ":" + std::to_string(n + 2) + ": column 't': " + what);
      };
      if (std::isnan(t)) fail("time is missing");
      if (n > 0) {
        const double tolerance = 1e-6 * ts + 4 * std::numeric_limits<double>::epsilon() * std::abs(t);
        if (std::abs(t - last_t - ts) > tolerance) {
          char text[160];
          std::snprintf(text, sizeof text, "time goes from %.10g to %.10g, expected a step of sample_time = %.10g",
                        last_t, t, ts);
          fail(text);
        }
      }
      last_t = t;
      if (!origin.known()) {
        for (std::size_t i = 0; i < m; ++i) u[i] = row[bound.inputs[i]];
        origin.offer(u.data());
      }
      ++n;
    }
  }
  bool all_sim = true;
  std::vector<bool> use_sim(p);
  for (std::size_t j = 0; j < p; ++j) {
    use_sim[j] = bound.sim[j].has_value();
    all_sim = all_sim && use_sim[j];
  }
  const std::size_t settle = settle_length(plant, settle_samples, record_settle_cap(n), all_sim);
  StreamedRecord out{MonitorBlueprint(plant, settings, plain_lags).build({}, settle), n, settle, {}};
  ResidualFrontEnd front(plant, origin.u0(), settle, std::move(use_sim));
  const auto reader = open();
  for (std::size_t k = 0; reader->next(row); ++k) {
    for (std::size_t i = 0; i < m; ++i) u[i] = row[bound.inputs[i]];
    for (std::size_t j = 0; j < p; ++j) {
      y[j] = row[bound.outputs[j]];
      sim_y[j] = bound.sim[j] ? row[*bound.sim[j]] : 0.0;
    }
    const ResidualFrontEnd::Stage stage = front.step(u.data(), y.data(), sim_y.data(), d.data());
    if (on_row && stage != ResidualFrontEnd::Stage::kNoOrigin) on_row(u.data(), d.data(), stage);
    if (stage != ResidualFrontEnd::Stage::kReady) continue;
    out.monitor.update(u.data(), d.data());
    if (on_sample) on_sample(k, out.monitor);
  }
  out.notes = reader->notes();
  return out;
}

}  // namespace mpm
