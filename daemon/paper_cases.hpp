// The paper's case studies (Chen, Xie & Su 2021, Sec. 4) run end to end:
// simulate the scenario under the MPC, compute the IMC residual, run the
// online monitor and the decussation baseline on the same data. Used by
// `mpm paper` and by the reproduction tests.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "core/decussation.hpp"
#include "core/granger_monitor.hpp"
#include "core/plant_model.hpp"

namespace mpm {

using Channel = std::pair<std::size_t, std::size_t>;  // (output, input)

struct PaperCase {
  const char* scenario;      // sim scenario name
  const char* paper_result;  // what the paper reports, for the printout
  std::vector<Channel> truth;  // channels that really differ
  bool unstable;             // the paper's unanalysable integrator case
  std::size_t samples;       // record length the verdict needs in our loop
};

const std::vector<PaperCase>& paper_cases();

struct PaperCaseResult {
  PlantModel plant;
  GrangerMonitor monitor;
  DecussationResult decussation;
  std::vector<Channel> located;  // record_verdict(): located over the whole record
  std::vector<bool> by_gamma;    // per channel (output major): located by the gamma rule
  bool diverging = false;        // some loop diverged: no verdict
  std::size_t samples = 0;
};

// Simulates `samples` samples with `seed` and analyses them. Throws on an
// unknown scenario or invalid plant file.
PaperCaseResult run_paper_case(const std::string& scenario, std::uint64_t seed, std::size_t samples,
                               const MonitorSettings& settings, const std::string& csv_out = "");

}  // namespace mpm
