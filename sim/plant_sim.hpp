// A simulated plant as the controller sees it: actuators -> process ->
// + disturbance -> sensors.
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

#include "sim/instruments.hpp"
#include "sim/process.hpp"

namespace mpm::sim {

class Plant {
 public:
  // The process's first n_controlled inputs are the controller's; any further
  // ones are extra (uncontrolled, e.g. a measured feed flow), fed in apply().
  Plant(std::unique_ptr<Process> process, std::size_t n_controlled, InputStage actuators,
        OutputStage sensors);

  std::size_t n_controlled() const noexcept { return n_controlled_; }
  std::size_t n_extra() const noexcept { return process_->n_inputs() - n_controlled_; }
  std::size_t n_outputs() const noexcept { return process_->n_outputs(); }

  // Real-time safe. Once per sample, before apply(): the measured outputs
  // y(k) = sensors(process output(k) + d(k)), deviation units.
  void measure(const double* disturbance, double* y) noexcept;
  // Real-time safe. u: commanded inputs u(k); extra: the extra inputs at k
  // (may be null when there are none). Moves the plant to k+1.
  void apply(const double* u, const double* extra) noexcept;
  void reset() noexcept;

 private:
  std::unique_ptr<Process> process_;
  std::size_t n_controlled_;
  InputStage actuators_;
  OutputStage sensors_;
  std::vector<double> process_in_;
  std::vector<double> process_out_;
};

}  // namespace mpm::sim
