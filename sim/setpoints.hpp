// Setpoint profiles: scheduled steps, random steps, a sine held in a zone.
#pragma once

#include <cstdint>
#include <limits>
#include <random>
#include <utility>
#include <vector>

namespace mpm::sim {

// One output's setpoint in deviation units:
//   r(k) = clip(level(k) + sine_amplitude sin(sine_frequency k Ts), zone)
// level(k) starts at `initial`, takes the scheduled steps, and (when
// random_amplitude > 0) jumps to initial + U(-a, a) after random periods.
struct SetpointSpec {
  double initial = 0.0;
  std::vector<std::pair<long, double>> steps;  // (sample, new level), in time order
  double random_amplitude = 0.0;
  long random_period_min = 300;  // samples
  long random_period_max = 600;
  double sine_amplitude = 0.0;
  double sine_frequency = 0.0;   // rad/s
  double zone_lower = -std::numeric_limits<double>::infinity();
  double zone_upper = std::numeric_limits<double>::infinity();
};

class SetpointGenerator {
 public:
  SetpointGenerator() = default;
  // Throws std::invalid_argument for a bad spec. Random steps are
  // deterministic for a seed (their own stream, independent of the noise).
  SetpointGenerator(std::vector<SetpointSpec> specs, double sample_time, std::uint64_t seed);

  // Real-time safe. Call with k = k0, k0+1, ... (negative k during warm-up
  // gives the initial level).
  void at(long k, double* r) noexcept;

 private:
  struct State {
    double level = 0.0;
    std::size_t next_step = 0;
    long next_random = 0;
  };
  long draw_period(const SetpointSpec& s) noexcept;

  std::vector<SetpointSpec> specs_;
  std::vector<State> state_;
  double sample_time_ = 1.0;
  std::mt19937_64 engine_;
};

}  // namespace mpm::sim
