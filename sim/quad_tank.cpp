#include "sim/quad_tank.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <tuple>

namespace mpm::sim {
namespace {

double sq(double x) { return x * x; }

void require_positive(double x, const std::string& name) {
  if (!(x > 0.0) || !std::isfinite(x)) throw std::invalid_argument("quad tank: " + name + " must be > 0");
}

// Outflow velocity sqrt(2 g h) of a tank; an empty tank does not drain.
double outflow_speed(const QuadTankParams& p, double h) noexcept {
  return std::sqrt(2.0 * p.gravity * std::max(h, 0.0));
}

// Time constant T_i = A_i/a_i sqrt(2 h_i / g) of tank i at level h.
double time_constant(const QuadTankParams& p, std::size_t i, double h) {
  return p.tank_area[i] / p.outlet_area[i] * std::sqrt(2.0 * h / p.gravity);
}

ContinuousTf first_order(double gain, double t) { return {{gain}, {t, 1.0}, 0.0}; }
ContinuousTf second_order(double gain, double ta, double tb) { return {{gain}, {ta * tb, ta + tb, 1.0}, 0.0}; }

}  // namespace

void QuadTankParams::validate() const {
  for (std::size_t i = 0; i < 4; ++i) {
    require_positive(tank_area[i], "tank_area[" + std::to_string(i) + "]");
    require_positive(outlet_area[i], "outlet_area[" + std::to_string(i) + "]");
  }
  for (std::size_t i = 0; i < 2; ++i) {
    require_positive(pump_gain[i], "pump_gain[" + std::to_string(i) + "]");
    require_positive(pump_voltage[i], "pump_voltage[" + std::to_string(i) + "]");
    if (!(valve_split[i] > 0.0 && valve_split[i] < 1.0))
      throw std::invalid_argument("quad tank: valve_split must be in (0, 1)");
  }
  require_positive(gravity, "gravity");
  require_positive(sensor_gain, "sensor_gain");
  if (substeps < 1) throw std::invalid_argument("quad tank: substeps must be >= 1");
}

std::array<double, 4> steady_levels(const QuadTankParams& p, const std::array<double, 2>& v) {
  const double f1 = p.pump_gain[0] * v[0], f2 = p.pump_gain[1] * v[1];
  const std::array<double, 4> inflow{p.valve_split[0] * f1 + (1.0 - p.valve_split[1]) * f2,
                                     p.valve_split[1] * f2 + (1.0 - p.valve_split[0]) * f1,
                                     (1.0 - p.valve_split[1]) * f2, (1.0 - p.valve_split[0]) * f1};
  std::array<double, 4> h{};
  for (std::size_t i = 0; i < 4; ++i) h[i] = sq(inflow[i] / p.outlet_area[i]) / (2.0 * p.gravity);
  return h;
}

std::array<double, 4> level_rates(const QuadTankParams& p, const std::array<double, 4>& h,
                                  const std::array<double, 2>& v) {
  std::array<double, 4> q{};  // outflow of each tank, cm^3/s
  for (std::size_t i = 0; i < 4; ++i) q[i] = p.outlet_area[i] * outflow_speed(p, h[i]);
  const double f1 = p.pump_gain[0] * v[0], f2 = p.pump_gain[1] * v[1];
  const auto& g = p.valve_split;
  const auto& area = p.tank_area;
  return {(-q[0] + q[2] + g[0] * f1) / area[0], (-q[1] + q[3] + g[1] * f2) / area[1],
          (-q[2] + (1.0 - g[1]) * f2) / area[2], (-q[3] + (1.0 - g[0]) * f1) / area[3]};
}

// Jacobian of the tank equations at the steady state (Johansson 2000, eq. 3):
// each tank is a lag T_i; the upper tanks drain into the lower ones.
PlantModel linearised_quad_tank(const QuadTankParams& p, double sample_time) {
  p.validate();
  const auto h = steady_levels(p, p.pump_voltage);
  std::array<double, 4> t{};
  for (std::size_t i = 0; i < 4; ++i) t[i] = time_constant(p, i, h[i]);
  const double kc = p.sensor_gain;
  const auto& g = p.valve_split;
  const auto& k = p.pump_gain;
  const double c11 = g[0] * k[0] * kc * t[0] / p.tank_area[0];
  const double c12 = (1.0 - g[1]) * k[1] * kc * t[0] / p.tank_area[0];
  const double c21 = (1.0 - g[0]) * k[0] * kc * t[1] / p.tank_area[1];
  const double c22 = g[1] * k[1] * kc * t[1] / p.tank_area[1];

  PlantModel m;
  m.name = "quadruple-tank";
  m.sample_time = sample_time;
  m.inputs = {"pump1", "pump2"};
  m.outputs = {"level1", "level2"};
  const ContinuousTf g11 = first_order(c11, t[0]), g12 = second_order(c12, t[0], t[2]);
  const ContinuousTf g21 = second_order(c21, t[1], t[3]), g22 = first_order(c22, t[1]);
  const std::array<std::tuple<std::size_t, std::size_t, ContinuousTf>, 4> channels{
      {{0, 0, g11}, {0, 1, g12}, {1, 0, g21}, {1, 1, g22}}};
  for (const auto& [out, in, tf] : channels)
    m.channels.push_back({out, in, discretize_zoh(tf, sample_time), false, tf});
  const std::array<double, 2> pole{0.85, 0.9};
  for (double a : pole) m.noise.push_back(NoiseModel{DiscreteTf{{1.0}, {1.0, -a}, 0}, 1e-4});
  m.operating_point = OperatingPoint{{p.pump_voltage[0], p.pump_voltage[1]}, {kc * h[0], kc * h[1]}};
  return m;
}

QuadTankProcess::QuadTankProcess(const QuadTankParams& p, double sample_time)
    : p_(p), sample_time_(sample_time) {
  p_.validate();
  require_positive(sample_time, "sample_time");
  h0_ = steady_levels(p_, p_.pump_voltage);
  h_ = h0_;
}

void QuadTankProcess::output(double* y) const noexcept {
  y[0] = p_.sensor_gain * (h_[0] - h0_[0]);
  y[1] = p_.sensor_gain * (h_[1] - h0_[1]);
}

// Classical RK4 over `substeps` steps with the pump voltages held (ZOH);
// pumps cannot run backwards, tanks cannot hold less than nothing.
void QuadTankProcess::advance(const double* u) noexcept {
  const std::array<double, 2> v{std::max(p_.pump_voltage[0] + u[0], 0.0),
                                std::max(p_.pump_voltage[1] + u[1], 0.0)};
  const double dt = sample_time_ / p_.substeps;
  for (int s = 0; s < p_.substeps; ++s) {
    auto shifted = [&](const std::array<double, 4>& k, double f) {
      std::array<double, 4> x{};
      for (std::size_t i = 0; i < 4; ++i) x[i] = h_[i] + f * k[i];
      return x;
    };
    const auto k1 = level_rates(p_, h_, v);
    const auto k2 = level_rates(p_, shifted(k1, dt / 2), v);
    const auto k3 = level_rates(p_, shifted(k2, dt / 2), v);
    const auto k4 = level_rates(p_, shifted(k3, dt), v);
    for (std::size_t i = 0; i < 4; ++i)
      h_[i] = std::max(h_[i] + dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]), 0.0);
  }
}

void QuadTankProcess::reset() noexcept { h_ = h0_; }

}  // namespace mpm::sim
