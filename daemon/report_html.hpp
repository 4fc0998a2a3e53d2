// `mpm diagnose --html`: one self-contained HTML file an engineer opens
// offline. It shows, per output, the recording against the nominal and the
// corrected model's prediction, the residual before and after the correction
// (in time, and as an autocorrelation with its 95 % bounds), the residual's
// cross-correlation with each input (what MATLAB's `resid` shows), the fit %
// (NRMSE, MATLAB's `compare`) before and after, the nominal and fitted step
// response of every finding, the Granger F, p and gamma per channel, for
// each located loop the paper's location plots (residual variance against
// AR order with 0, 1, 2 lags of each input; the AR part fitted beside each
// input's lags against 1 - N^-1: core/paper_plots.hpp), and the live
// detector's statistic over the record (T_W / h_W, as `mpm monitor` and
// mpmd compute it: DetectorTrace below, fed by the same monitor run).
//
// The plots are drawn by dygraphs, the JavaScript charting library Debian
// packages (libjs-dygraphs), read from its installed file and inlined into
// the page so that it needs no network and no other file.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "core/diagnosis.hpp"
#include "core/granger_monitor.hpp"
#include "core/plant_model.hpp"
#include "daemon/offline.hpp"
#include "daemon/plant_writer.hpp"

namespace mpm {

// The live detector's evidence per output over a record, sampled after
// every update of the monitor run that the diagnosis uses (monitor_record's
// per-sample callback, so the same front end and the same statistics as
// `mpm monitor`): per bin of `stride` samples the largest T_W / h_W of the
// all-inputs statistic and of the focused one (core/paper_plots.hpp:
// detector_evidence). Bins are sized at
// construction; parts of the monitor on separate threads write disjoint
// outputs.
class DetectorTrace {
 public:
  DetectorTrace(std::size_t outputs, std::size_t samples, std::size_t points = 2000);
  PartSampleCallback callback();
  std::size_t stride() const noexcept { return stride_; }
  std::size_t bins() const noexcept { return bins_; }
  // NaN in a bin with no look of that statistic.
  double all(std::size_t j, std::size_t bin) const { return all_[j][bin]; }
  double focused(std::size_t j, std::size_t bin) const { return focused_[j][bin]; }

 private:
  std::size_t stride_ = 1, bins_ = 0;
  std::vector<std::vector<double>> all_, focused_;
};

struct ReportInputs {
  const PlantModel& plant;
  const CorrectedPlant& corrected;
  const diagnosis::Problem& problem;
  const GrangerMonitor& monitor;
  const RecordVerdict& verdict;
  const diagnosis::Result& result;
  std::string plant_path, data_path;
  const DetectorTrace* trace = nullptr;  // the detector section is left out without it
  diagnosis::Settings settings;  // what the diagnosis was made with (its level, its held-out phase)
};

// Where the dygraphs script is read from: $MPM_DYGRAPHS_JS when set, else
// the path libjs-dygraphs installs.
std::string dygraphs_path();

// The page. Throws std::runtime_error naming the file when the dygraphs
// script cannot be read.
std::string report_html(const ReportInputs& in);

// Fit % of a prediction error e against the signal y (both with their means
// removed over the finite samples): 100 (1 - |e| / |y - mean y|), MATLAB
// compare's NRMSE fit. NaN when y is constant or there are no samples.
double fit_percent(const Eigen::VectorXd& y, const Eigen::VectorXd& e);

}  // namespace mpm
