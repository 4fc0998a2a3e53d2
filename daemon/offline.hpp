// Offline glue shared by the `mpm` commands that read a recording: turns a
// plant and a recording into the residual series the monitor watches.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "config/plant_loader.hpp"
#include "core/diagnosis.hpp"
#include "core/granger_monitor.hpp"
#include "core/monitor_front_end.hpp"
#include "core/plant_model.hpp"

namespace mpm {

struct ResidualSeries {
  Eigen::MatrixXd u;         // samples x inputs, absolute units (NaN = missing)
  Eigen::MatrixXd residual;  // samples x outputs: y - sim_y, or y - G_M (u - u0)
  std::vector<bool> from_simulation;  // per output: sim_<output> column used
  std::size_t transient = 0;  // leading samples that carry the model's start-up transient
};

// The residuals of a whole recording by the front end mpmd uses
// (core/monitor_front_end.hpp): u0 by its rule (the operating point, else
// the recording's first complete input row), y - sim_y for the outputs with
// a sim_ column, and the settle time (`settle_samples` >= 0: that many;
// else none when every output has a sim_ column, else the plant's settling
// time capped at a tenth of the record). The outputs' offset stays in the
// residual (the monitor's intercept absorbs it).
ResidualSeries compute_residuals(const PlantModel& plant, const config::Recording& rec,
                                 const config::BoundRecording& bound, int settle_samples = -1);

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

// What every diagnosis hands to the hypothesis fits (core/diagnosis.hpp)
// from a plant and a window of samples (samples x inputs, absolute units;
// samples x outputs): the deviation inputs of the front end (u0 by its rule,
// the last good value held over missing samples), the residuals, the plant's
// channels and noise models; no extra columns, no monitor verdict.
diagnosis::Problem plant_problem(const PlantModel& plant, const Eigen::MatrixXd& u, const Eigen::MatrixXd& residual);
// What `mpm diagnose` hands to them: the plant problem of the recording, its
// extra columns, and the monitor's verdict on the record.
diagnosis::Problem diagnosis_problem(const PlantModel& plant, const config::Recording& rec,
                                     const config::BoundRecording& bound, const ResidualSeries& series,
                                     const RecordVerdict& verdict);

// Builds a monitor of the plant and settings at hand for some of its outputs.
using MonitorPartFactory = std::function<GrangerMonitor(OutputRange)>;
// Called after each update of a part, on that part's thread, with the sample
// index; only the part's outputs (first_modelled_output() ..
// end_modelled_output()) are meaningful in it.
using PartSampleCallback = std::function<void(std::size_t, const GrangerMonitor&)>;

// Parts of the monitor the blueprint builds (core/monitor_front_end.hpp).
MonitorPartFactory monitor_factory(const PlantModel& plant, const MonitorSettings& settings, bool plain_lags = false,
                                   std::size_t front_end_settle = MonitorBlueprint::kSettleUnknown);

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

// `mpm diagnose` from a loaded recording to its findings, the one pipeline
// the command runs and `mpm bench` times: residuals by the front end, the
// Granger monitor over the record (forgetting 1, outputs over threads), its
// family-wise verdict, then, where the record holds enough usable samples,
// the structured hypotheses on every core. The recording's columns are
// released before the fits run: they need only the problem's.
struct RecordDiagnosisOptions {
  diagnosis::Progress progress = nullptr;    // progress lines (may be empty)
  PartSampleCallback on_sample;              // the monitor after each sample (the HTML report's trace)
  // The diagnosis' settings: the engineer's (the rows of
  // diagnosis::Settings::fields()) and verbose (every hypothesis' statistics
  // to `progress`); the pipeline sets the threads. Its alpha is the
  // false-alarm level per look, and the monitor's record verdict is made at
  // kUnexplainedShare of it.
  diagnosis::Settings settings;
};

// The share of the false-alarm level that `mpm diagnose` gives the
// monitor's record verdict, beside the structured tests' full level.
inline constexpr double kUnexplainedShare = 0.1;

// The most often a record without mismatch gets a finding at level alpha:
// the process rounds and the disturbance-model look spend alpha each, the
// monitor's verdict kUnexplainedShare of it (union bound).
inline double healthy_finding_bound(double alpha) { return (2.0 + kUnexplainedShare) * alpha; }

struct RecordDiagnosis {
  std::size_t samples = 0;  // rows of the recording
  GrangerMonitor monitor;
  RecordVerdict verdict{};  // at kUnexplainedShare of alpha, family-wise
  // Samples the tests need; with fewer usable (every input and output finite,
  // after the model settles) the record cannot be decided and no hypothesis
  // is fitted (problem and result stay empty).
  std::uint64_t needed = 0;
  diagnosis::Problem problem{};
  diagnosis::Result result{};

  bool decided() const { return monitor.counters().used >= needed; }
};

RecordDiagnosis diagnose_record(const PlantModel& plant, config::Recording&& rec, const RecordDiagnosisOptions& options);

}  // namespace mpm
