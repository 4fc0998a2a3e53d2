// Coloured measurement disturbance d_j = N_j(q) a_j, a_j white Gaussian.
#pragma once

#include <cstdint>
#include <random>
#include <vector>

#include "core/plant_model.hpp"
#include "core/transfer_function.hpp"

namespace mpm::sim {

struct NoiseChannel {
  DiscreteTf filter{{1.0}, {1.0}, 0};  // N_j
  double variance = 1.0;               // of a_j
};

// The plant file's noise section: N and var(a) per output; an output without
// an entry gets white noise of `default_variance`, one without a variance gets
// `default_variance`.
std::vector<NoiseChannel> noise_channels(const PlantModel& model, double default_variance);

class NoiseSource {
 public:
  NoiseSource() = default;
  // Deterministic for a seed. scale multiplies every a_j (0 = noiseless).
  NoiseSource(const std::vector<NoiseChannel>& channels, std::uint64_t seed, double scale = 1.0);

  // Real-time safe. Writes d(k) for every output.
  void draw(double* d) noexcept;

 private:
  std::mt19937_64 engine_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  std::vector<double> stddev_;
  std::vector<DiscreteFilter> filters_;
};

}  // namespace mpm::sim
