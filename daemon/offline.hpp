// Offline glue shared by the `mpm` commands that read a recording: turns a
// plant and a recording into the residual series the monitor watches.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "config/plant_loader.hpp"
#include "core/granger_monitor.hpp"
#include "core/plant_model.hpp"

namespace mpm {

struct ResidualSeries {
  Eigen::MatrixXd u;         // samples x inputs, absolute units (NaN = missing)
  Eigen::MatrixXd residual;  // samples x outputs: y - sim_y, or y - G_M (u - u0)
  std::vector<bool> from_simulation;  // per output: sim_<output> column used
  std::size_t transient = 0;  // leading samples that carry the model's start-up transient
};

// formats.md: u0 = operating_point.inputs, else the recording's first
// complete input sample; the outputs' offset stays in the residual (the
// monitor's intercept absorbs it).
ResidualSeries compute_residuals(const PlantModel& plant, const config::Recording& rec,
                                 const config::BoundRecording& bound);

// Noise-model AR coefficients (1 - N^-1) per output, for the gamma index.
std::vector<std::optional<std::vector<double>>> noise_ar(const PlantModel& plant, int order);

// Variance of each output's residual with a matched model (N's output
// variance), 0 where the plant file gives no noise model or no variance.
std::vector<double> reference_variances(const PlantModel& plant);

// Runs the online monitor over the series (after the transient), calling
// `on_sample(k, monitor)` after each update when given.
template <typename OnSample>
void run_monitor(GrangerMonitor& monitor, const ResidualSeries& s, OnSample&& on_sample) {
  for (Eigen::Index k = static_cast<Eigen::Index>(s.transient); k < s.u.rows(); ++k) {
    const Eigen::VectorXd u = s.u.row(k).transpose();
    const Eigen::VectorXd d = s.residual.row(k).transpose();
    monitor.update(u.data(), d.data());
    on_sample(static_cast<std::size_t>(k), monitor);
  }
}

}  // namespace mpm
