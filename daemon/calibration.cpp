#include "daemon/calibration.hpp"

#include <algorithm>
#include <stdexcept>

#include "config/plant_loader.hpp"
#include "daemon/offline.hpp"
#include "sim/closed_loop.hpp"
#include "sim/scenarios.hpp"

namespace mpm {

NullRun null_alarm_run(const PlantModel& plant, const MonitorSettings& settings, std::uint64_t seed,
                       std::size_t samples, const std::vector<std::vector<double>>& levels,
                       const std::string& scenario) {
  const sim::Scenario* sc = sim::find_scenario(scenario);
  if (!sc) throw std::invalid_argument("no scenario " + scenario);
  sim::ClosedLoop loop(plant, sim::scenario_loop(*sc, plant), seed);
  const config::Recording rec = sim::simulate(loop, samples, "null");
  const config::BoundRecording bound = config::bind(plant, rec);
  const ResidualSeries series = compute_residuals(plant, rec, bound);
  GrangerMonitor monitor = MonitorBlueprint(plant, settings).build({}, series.transient);
  const SequentialDetector& det = monitor.detector();
  const std::size_t p = plant.n_outputs(), kw = det.windows();
  const double d = static_cast<double>(det.dof());

  NullRun out;
  out.excursions.assign(kw, {});
  for (std::size_t k = 0; k < kw && k < levels.size(); ++k) out.excursions[k].assign(levels[k].size(), 0);
  // Above-state per (output, window, level).
  std::vector<char> above(p * kw * 8, 0);
  std::vector<char> raised(p, 0);
  const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> u = series.u;
  const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> r = series.residual;
  for (std::size_t s = series.transient; s < rec.samples(); ++s) {
    monitor.update(u.row(static_cast<Eigen::Index>(s)).data(), r.row(static_cast<Eigen::Index>(s)).data());
    ++out.samples;
    for (std::size_t j = 0; j < p; ++j) {
      const bool now = monitor.loop(j).alarm;
      if (now && !raised[j]) {
        out.raises.push_back(out.samples - 1);
        out.raised_outputs.push_back(j);
        std::size_t named = plant.n_inputs();
        for (std::size_t i = 0; i < plant.n_inputs(); ++i)
          if (monitor.channel(j, i).alarm) named = i;
        out.raised_inputs.push_back(named);
      }
      raised[j] = now ? 1 : 0;
      for (std::size_t k = 0; k < kw && k < levels.size(); ++k)
        for (std::size_t l = 0; l < levels[k].size() && l < 8; ++l) {
          const double h = levels[k][l], t = det.last(j, k);
          char& a = above[(j * kw + k) * 8 + l];
          if (!a && t > h) {
            a = 1;
            ++out.excursions[k][l];
          } else if (a && t < d + 0.5 * (h - d)) {
            a = 0;
          }
        }
    }
  }
  return out;
}

Calibration fit_thresholds(const GrangerMonitor& shape, const std::vector<std::vector<double>>& levels,
                           const std::vector<std::vector<std::size_t>>& excursions, double output_samples,
                           std::size_t min_count) {
  const SequentialDetector& det = shape.detector();
  const MonitorSettings& s = shape.settings();
  const std::size_t kw = det.windows();
  const double d = static_cast<double>(det.dof());
  const double period = static_cast<double>(kw);
  const double share = s.detector.rate_per_sample() / static_cast<double>(shape.n_outputs() * kw);
  Calibration c;
  for (std::size_t k = 0; k < kw; ++k) {
    double constant = s.detector.crossing_constant;
    std::size_t count = 0;
    for (std::size_t l = 0; k < levels.size() && l < levels[k].size(); ++l) {
      const std::size_t n = excursions[k][l];
      if (n < min_count) continue;
      // Highest level with enough events: closest to the thresholds' tail.
      const double unit = crossing_rate(levels[k][l], d, det.window(k), period, 1.0);
      constant = std::max(static_cast<double>(n) / output_samples / unit, 1e-3);
      count = n;
    }
    c.constants.push_back(constant);
    c.counts.push_back(count);
    c.thresholds.push_back(crossing_threshold(share, d, det.window(k), period, constant));
  }
  return c;
}

}  // namespace mpm
