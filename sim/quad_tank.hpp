// The nonlinear quadruple tank of Johansson (2000): two pumps feed four tanks
// through two three-way valves; the two lower levels are measured.
//
//   dh1/dt = -a1/A1 sqrt(2g h1) + a3/A1 sqrt(2g h3) + g1 k1/A1 v1
//   dh2/dt = -a2/A2 sqrt(2g h2) + a4/A2 sqrt(2g h4) + g2 k2/A2 v2
//   dh3/dt = -a3/A3 sqrt(2g h3) + (1-g2) k2/A3 v2
//   dh4/dt = -a4/A4 sqrt(2g h4) + (1-g1) k1/A4 v1
//   y = kc (h1, h2)
//
// Parameters default to Johansson's minimum-phase setting P-, which is what
// the benchmark recordings (data/qt_*) use. (The seed paper's Table 7 has
// pump gains 3.14 and 3.29 and swaps the labels of the two areas; we keep
// Johansson's values so that config/quad-tank.yaml matches the benchmark.)
#pragma once

#include <array>

#include "core/plant_model.hpp"
#include "sim/process.hpp"

namespace mpm::sim {

struct QuadTankParams {
  std::array<double, 4> tank_area{28.0, 32.0, 28.0, 32.0};      // A_i, cm^2
  std::array<double, 4> outlet_area{0.071, 0.057, 0.071, 0.057};  // a_i, cm^2
  std::array<double, 2> pump_gain{3.33, 3.35};                  // k_i, cm^3/(V s)
  std::array<double, 2> valve_split{0.70, 0.60};                // gamma_i: share to the lower tank
  double gravity = 981.0;                                       // cm/s^2
  double sensor_gain = 0.50;                                    // kc, V/cm
  std::array<double, 2> pump_voltage{3.0, 3.0};                 // operating point v0, V
  int substeps = 10;                                            // RK4 steps per sample

  void validate() const;  // throws std::invalid_argument naming the bad value
};

// Levels h (cm) at which constant pump voltages v hold the tanks still.
std::array<double, 4> steady_levels(const QuadTankParams& p, const std::array<double, 2>& v);

// dh/dt at levels h and pump voltages v (levels below 0 count as empty).
std::array<double, 4> level_rates(const QuadTankParams& p, const std::array<double, 4>& h,
                                  const std::array<double, 2>& v);

// The 2x2 linear model (continuous channels, ZOH at sample_time) at the
// operating point p.pump_voltage, with inputs pump1, pump2 (V) and outputs
// level1, level2 (V), the operating point set, and AR(1) noise models.
PlantModel linearised_quad_tank(const QuadTankParams& p, double sample_time);

class QuadTankProcess final : public Process {
 public:
  // Starts at rest at the steady state of p.pump_voltage; inputs and outputs
  // are deviations from that point (V).
  QuadTankProcess(const QuadTankParams& p, double sample_time);

  std::size_t n_inputs() const noexcept override { return 2; }
  std::size_t n_outputs() const noexcept override { return 2; }
  void output(double* y) const noexcept override;
  void advance(const double* u) noexcept override;
  void reset() noexcept override;
  const std::array<double, 4>& levels() const noexcept { return h_; }

 private:
  QuadTankParams p_;
  double sample_time_;
  std::array<double, 4> h0_;
  std::array<double, 4> h_;
};

}  // namespace mpm::sim
