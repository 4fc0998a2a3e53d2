// Offline glue shared by the `mpm` commands that read a recording: turns a
// plant and a recording into the residual series the monitor watches.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "config/plant_loader.hpp"
#include "core/diagnosis.hpp"
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

// The settings with what the plant file knows filled in: the detector's
// sample time (0 in the settings = the plant's).
MonitorSettings for_plant(MonitorSettings settings, const PlantModel& plant);

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
  Eigen::VectorXd u(s.u.cols()), d(s.residual.cols());
  for (Eigen::Index k = static_cast<Eigen::Index>(s.transient); k < s.u.rows(); ++k) {
    u = s.u.row(k).transpose();
    d = s.residual.row(k).transpose();
    monitor.update(u.data(), d.data());
    on_sample(static_cast<std::size_t>(k), monitor);
  }
}

// What `mpm diagnose` hands to the hypothesis fits (core/diagnosis.hpp):
// deviation inputs (the last good value held over missing samples), the
// residual series, the recording's extra columns, the plant's channels and
// noise models, and the monitor's verdict on the record.
diagnosis::Problem diagnosis_problem(const PlantModel& plant, const config::Recording& rec,
                                     const config::BoundRecording& bound, const ResidualSeries& series,
                                     const RecordVerdict& verdict);

// Builds a monitor of the plant and settings at hand for some of its outputs.
using MonitorPartFactory = std::function<GrangerMonitor(OutputRange)>;
// Called after each update of a part, on that part's thread, with the sample
// index; only the part's outputs (first_modelled_output() ..
// end_modelled_output()) are meaningful in it.
using PartSampleCallback = std::function<void(std::size_t, const GrangerMonitor&)>;

// Monitors of `plant` with `settings`: its noise models (for gamma) and
// reference variances, and model-filtered regressors unless `plain_lags`.
MonitorPartFactory monitor_factory(const PlantModel& plant, const MonitorSettings& settings, bool plain_lags = false);

// Threads worth using for a monitor of `outputs` outputs on this machine:
// one per core, at most one per output, at least one.
std::size_t replay_threads(std::size_t outputs);

// The same as run_monitor over `threads` threads: the outputs' statistics are
// independent, so each thread runs a monitor of a contiguous part of the
// outputs over the whole record, and `monitor` then adopts every part (bit
// for bit what one thread computes; see OutputRange). Samples [first,
// samples) of `u` (samples x inputs) and `residual` (samples x outputs), one
// sample contiguous.
void run_monitor_parallel(GrangerMonitor& monitor, const double* u, const double* residual, std::size_t first,
                          std::size_t samples, std::size_t threads, const MonitorPartFactory& make_part,
                          const PartSampleCallback& on_sample = {});
// The same over a residual series (after its transient).
void run_monitor_parallel(GrangerMonitor& monitor, const ResidualSeries& s, std::size_t threads,
                          const MonitorPartFactory& make_part, const PartSampleCallback& on_sample = {});
// The whole plant's monitor after the series (after its transient),
// replayed over `threads` threads by run_monitor_parallel.
GrangerMonitor monitor_record(const PlantModel& plant, const ResidualSeries& s, const MonitorSettings& settings,
                              std::size_t threads, bool plain_lags = false, const PartSampleCallback& on_sample = {});

}  // namespace mpm
