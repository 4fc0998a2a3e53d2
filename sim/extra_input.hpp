// Extra recorded signals that drive the plant but not the model: the
// `unmodeled_input` physics (e.g. a measured feed flow the model left out).
#pragma once

#include <cstdint>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "core/transfer_function.hpp"

namespace mpm::sim {

// w(k) = operating_value + x(k), x an AR(1) process with pole `pole` and
// standard deviation `stddev`; it acts on outputs through `drives`. A recorded
// one is a column of the recording (`unmodeled_input`); an unrecorded one is
// an unmeasured disturbance that changes the disturbance dynamics.
struct ExtraInputSpec {
  std::string name;  // CSV column of the recording
  bool recorded = true;
  double operating_value = 0.0;
  double pole = 0.98;
  double stddev = 0.1;
  std::vector<std::pair<std::string, ContinuousTf>> drives;  // (output name, channel)
};

class ExtraInputSource {
 public:
  ExtraInputSource() = default;
  // Throws std::invalid_argument for a bad spec. Own random stream.
  ExtraInputSource(const std::vector<ExtraInputSpec>& specs, std::uint64_t seed);

  std::size_t size() const noexcept { return pole_.size(); }
  // Real-time safe. Writes the deviations x(k) of every extra input.
  void draw(double* x) noexcept;

 private:
  std::mt19937_64 engine_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  std::vector<double> pole_, innovation_std_, state_;
};

}  // namespace mpm::sim
