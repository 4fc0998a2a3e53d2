// The physics of a simulated plant, without its instruments: deviation
// inputs in, deviation outputs out, one sample at a time.
#pragma once

#include <cstddef>

namespace mpm::sim {

// Sampled like a real process: output() is y(k), which depends on inputs up
// to u(k-1) only (every plant is strictly proper, so the controller can read
// y(k) before it chooses u(k)); advance(u(k)) holds u(k) over one sample
// period and moves the process to k+1.
class Process {
 public:
  virtual ~Process() = default;
  virtual std::size_t n_inputs() const noexcept = 0;
  virtual std::size_t n_outputs() const noexcept = 0;
  // Real-time safe.
  virtual void output(double* y) const noexcept = 0;
  // Real-time safe.
  virtual void advance(const double* u) noexcept = 0;
  // Back to rest at the operating point (zero deviation).
  virtual void reset() noexcept = 0;
};

}  // namespace mpm::sim
