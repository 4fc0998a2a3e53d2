#include "sim/builtin_plants.hpp"

// Copies of config/wood-berry.yaml, config/quad-tank.yaml and
// config/quad-tank-4x4.yaml, written by sim/gen_builtin_plants.py
// (tests/sim/test_scenarios.cpp checks that the files and these copies
// describe the same plants).
namespace mpm::sim {
namespace {

constexpr std::string_view kWoodBerry = R"yaml(# Wood-Berry distillation column (Wood & Berry 1973), the 2x2 case study of
# Chen, Xie & Su (2021), Sec. 4.1, in its discrete ZOH form at 1 min:
#   G11 = 0.744 q^-2 / (1 - 0.9419 q^-1)    G12 = -0.8789 q^-4 / (1 - 0.9535 q^-1)
#   G21 = 0.5786 q^-8 / (1 - 0.9123 q^-1)   G22 = -1.302 q^-4 / (1 - 0.9329 q^-1)
# u1 = reflux flow, u2 = steam flow; y1 = top composition, y2 = bottom composition.
# wood-berry-continuous.yaml is the same plant in continuous form.
plant: wood-berry
sample_time: 1
inputs:  [u1, u2]
outputs: [y1, y2]

model:
  - output: y1
    input: u1
    num: [0.744]
    den: [1, -0.9419]
    delay: 2
  - output: y1
    input: u2
    num: [-0.8789]
    den: [1, -0.9535]
    delay: 4
  - output: y2
    input: u1
    num: [0.5786]
    den: [1, -0.9123]
    delay: 8
  - output: y2
    input: u2
    num: [-1.302]
    den: [1, -0.9329]
    delay: 4

# N = diag(1/(1 - 0.8 q^-1), 1/(1 - 0.9 q^-1)), var(a1) = var(a2) = 1
noise:
  - output: y1
    num: [1]
    den: [1, -0.8]
    variance: 1
  - output: y2
    num: [1]
    den: [1, -0.9]
    variance: 1

operating_point:
  inputs: [15, 12]
  outputs: [90, 5]
)yaml";

constexpr std::string_view kQuadTank = R"yaml(# Quadruple tank of Johansson (2000), minimum-phase setting P-: pump voltages
# (V) in, lower-tank levels measured as kc*h (V, kc = 0.5 V/cm) out.
# Linearised at v0 = (3, 3) V, h0 = (12.263, 12.783, 1.634, 1.409) cm:
#   G11 = g1 c1/(T1 s+1)            G12 = (1-g2) c12/((T1 s+1)(T3 s+1))
#   G21 = (1-g1) c21/((T2 s+1)(T4 s+1))   G22 = g2 c2/(T2 s+1)
# with T_i = A_i/a_i sqrt(2 h_i/g) = (62.36, 90.63, 22.76, 30.09) s.
# The nonlinear plant behind it is built into the simulator (sim/quad_tank.hpp,
# scenarios quad-tank-*); this file is what its MPC and the monitor use, and
# equals the benchmark's data/qt_*/plant.yaml plus the operating point.
plant: quadruple-tank
sample_time: 5
inputs:  [pump1, pump2]
outputs: [level1, level2]

model:
  - output: level1
    input: pump1
    continuous: {num: [2.595566811], den: [62.35595942, 1], dead_time: 0}
  - output: level1
    input: pump2
    continuous: {num: [1.492089029], den: [1419.307002, 85.11732843, 1], dead_time: 0}
  - output: level2
    input: pump1
    continuous: {num: [1.414686523], den: [2727.047513, 120.7202781, 1], dead_time: 0}
  - output: level2
    input: pump2
    continuous: {num: [2.846366278], den: [90.63056805, 1], dead_time: 0}

noise:
  - output: level1
    num: [1]
    den: [1, -0.85]
    variance: 0.0001
  - output: level2
    num: [1]
    den: [1, -0.9]
    variance: 0.0001

operating_point: {inputs: [3, 3], outputs: [6.13148376, 6.391579202]}
)yaml";

constexpr std::string_view kQuadTank4x4 = R"yaml(# The seed paper's 4x4 "quadruple tank" (Chen, Xie & Su 2021, Sec. 4.2): its
# linear transfer matrix, rows = outputs y1..y4, columns = inputs u1..u4.
# Reading of the garbled text extraction, checked for consistency: the
# first-order poles 0.011, 0.015, 0.016, 0.018, 0.026 recur across channels,
# and each second-order channel should be two of them in series:
#   G11 = 0.048/(s+0.016)   G12 = 0.0025/(s^2+0.028s+0.0002) (as printed: near
#       (s+0.017)(s+0.011); its roots are a complex pair with damping 0.99)
#   G13 = 0.35/(s+0.015)    G14 = 0.0096/(s^2+0.041s+0.0004)   (printed 0.41s:
#       read 0.041s = (s+0.015)(s+0.026), the poles of G13 and G34; with 0.41
#       the channel would have a 1000 s pole no other channel has)
#   G21 = 0.0009/(s+0.016)  G22 = 0.035/(s+0.011)
#   G23 = 0.0055/(s^2+0.024s+0.0002) (as printed; damping 0.85)
#   G24 = 0.325/(s+0.011)
#   G31 = 0  G32 = 0.078/(0.028s+0.25) (as printed: a 0.11 s lag, static at
#       this sample time)  G33 = 0  G34 = 0.37/(s+0.026)
#   G41 = 0.045/(s+0.018)   G42 = 0   G43 = 0.31/(s+0.018)   G44 = 0
# The paper's mismatch cases (scenarios quad-tank-g23-order, -g33-zero,
# -g32-integrator) read: G23 -> 0.0055/(s^2+0.04s+0.001); G33 = 0 ->
# 0.2/(s+0.02); G32 -> 0.078/((0.028s+0.25)s).
# Time in seconds; the sample time of 2 s resolves the 40-90 s tank time
# constants in a few thousand samples. Units are the paper's (unstated).
plant: quad-tank-4x4
sample_time: 2
inputs:  [u1, u2, u3, u4]
outputs: [y1, y2, y3, y4]

model:
  - {output: y1, input: u1, continuous: {num: [0.048], den: [1, 0.016]}}
  - {output: y1, input: u2, continuous: {num: [0.0025], den: [1, 0.028, 0.0002]}}
  - {output: y1, input: u3, continuous: {num: [0.35], den: [1, 0.015]}}
  - {output: y1, input: u4, continuous: {num: [0.0096], den: [1, 0.041, 0.0004]}}
  - {output: y2, input: u1, continuous: {num: [0.0009], den: [1, 0.016]}}
  - {output: y2, input: u2, continuous: {num: [0.035], den: [1, 0.011]}}
  - {output: y2, input: u3, continuous: {num: [0.0055], den: [1, 0.024, 0.0002]}}
  - {output: y2, input: u4, continuous: {num: [0.325], den: [1, 0.011]}}
  - {output: y3, input: u1, num: [0]}
  - {output: y3, input: u2, continuous: {num: [0.078], den: [0.028, 0.25]}}
  - {output: y3, input: u3, num: [0]}
  - {output: y3, input: u4, continuous: {num: [0.37], den: [1, 0.026]}}
  - {output: y4, input: u1, continuous: {num: [0.045], den: [1, 0.018]}}
  - {output: y4, input: u2, num: [0]}
  - {output: y4, input: u3, continuous: {num: [0.31], den: [1, 0.018]}}
  - {output: y4, input: u4, num: [0]}

noise:
  - {output: y1, num: [1], den: [1, -0.8], variance: 1}
  - {output: y2, num: [1], den: [1, -0.9], variance: 1}
  - {output: y3, num: [1], den: [1, -0.8], variance: 1}
  - {output: y4, num: [1], den: [1, -0.9], variance: 1}

# Table 8's initial setpoints (r1 = 8, r2 = 25, r3 = 12, r4 = 0); inputs at 0.
operating_point: {inputs: [0, 0, 0, 0], outputs: [8, 25, 12, 0]}
)yaml";

}  // namespace

std::optional<std::string_view> builtin_plant_text(std::string_view file_name) {
  if (file_name == "wood-berry.yaml") return kWoodBerry;
  if (file_name == "quad-tank.yaml") return kQuadTank;
  if (file_name == "quad-tank-4x4.yaml") return kQuadTank4x4;
  return std::nullopt;
}

}  // namespace mpm::sim
