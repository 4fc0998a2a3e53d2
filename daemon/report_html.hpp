// `mpm diagnose --html`: one self-contained HTML file an engineer opens
// offline. It shows, per output, the recording against the nominal and the
// corrected model's prediction, the residual before and after the correction
// (in time, and as an autocorrelation with its 95 % bounds), the residual's
// cross-correlation with each input (what MATLAB's `resid` shows), the fit %
// (NRMSE, MATLAB's `compare`) before and after, the nominal and fitted step
// response of every finding, and the Granger F, p and gamma per channel.
//
// The plots are drawn by dygraphs, the JavaScript charting library Debian
// packages (libjs-dygraphs), read from its installed file and inlined into
// the page so that it needs no network and no other file.
#pragma once

#include <string>

#include "core/diagnosis.hpp"
#include "core/granger_monitor.hpp"
#include "core/plant_model.hpp"
#include "daemon/offline.hpp"
#include "daemon/plant_writer.hpp"

namespace mpm {

struct ReportInputs {
  const PlantModel& plant;
  const CorrectedPlant& corrected;
  const diagnosis::Problem& problem;
  const GrangerMonitor& monitor;
  const RecordVerdict& verdict;
  const diagnosis::Result& result;
  std::string plant_path, data_path;
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
