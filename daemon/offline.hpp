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

// The nominal channels G_ji, output major, for the monitor's model-filtered
// regressors (nullopt where the model has no channel).
std::vector<std::optional<DiscreteTf>> channel_models(const PlantModel& plant);

// The verdict on a whole record, from the statistics after its last sample
// (with forgetting 1 they summarise the whole record; the alarm state with
// its hysteresis is for live use): a channel is located when its own
// conditional test rejects at the monitor's alpha; in a loop where none does
// but the joint test of all inputs rejects, the paper's two indices name the
// channel: among those whose AR part matches N^-1 (gamma < lambda^2), the
// one with the largest pairwise F. Diverging loops locate nothing.
struct RecordVerdict {
  std::vector<std::pair<std::size_t, std::size_t>> located;  // (output, input), row major
  std::vector<bool> loop_mismatch;                           // per output
  std::vector<bool> by_gamma;                                // per channel, output major
  bool diverging = false;
};
RecordVerdict record_verdict(const GrangerMonitor& monitor);

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
