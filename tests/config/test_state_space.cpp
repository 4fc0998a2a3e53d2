// State-space plants (formats.md 4.5; core/state_space.hpp): the channels
// the loader makes have the step responses of a direct simulation of the
// state space (discrete: the recursion itself; continuous: RK4 on a fine
// grid with the input held, sampled at sample_time); shared roots are
// cancelled; the disturbance model's spectrum is the process's; the quad
// tank written as a state space gives quad-tank.yaml's channels; shape
// errors name the file, line and key.
#include <cmath>
#include <complex>
#include <string>

#include <gtest/gtest.h>

#include "config/plant_loader.hpp"
#include "config_test_util.hpp"
#include "core/transfer_function.hpp"
#include "support/tf_step.hpp"

namespace mpm::config {
namespace {

using test::tf_step;

const ChannelModel* find(const PlantModel& p, std::size_t j, std::size_t i) { return p.channel(j, i); }

// A coupled, non-diagonal discrete plant: 3 states, 2 inputs, 2 outputs, D != 0.
constexpr const char* kDiscrete = R"(plant: ss
sample_time: 1
inputs: [u1, u2]
outputs: [y1, y2]
state_space:
  discrete: true
  A: [[0.9, 0.1, 0], [-0.05, 0.8, 0.2], [0, 0, 0.5]]
  B: [[1, 0], [0, 0.5], [0.3, 1]]
  C: [[1, 0, 0], [0, 1, 1]]
  D: [[0, 0.2], [0, 0]]
  input_delay: [0, 2]
)";

TEST(StateSpace, DiscreteStepResponsesEqualTheRecursion) {
  const PlantModel p = parse_plant(kDiscrete, "ss.yaml");
  const Eigen::Matrix3d a{{0.9, 0.1, 0}, {-0.05, 0.8, 0.2}, {0, 0, 0.5}};
  const Eigen::Matrix<double, 3, 2> b{{1, 0}, {0, 0.5}, {0.3, 1}};
  const Eigen::Matrix<double, 2, 3> c{{1, 0, 0}, {0, 1, 1}};
  const Eigen::Matrix2d d{{0, 0.2}, {0, 0}};
  for (std::size_t i = 0; i < 2; ++i) {
    // y(k) for u_i = 1 from k = delay on, x(0) = 0.
    const int delay = i == 1 ? 2 : 0;
    Eigen::Vector3d x = Eigen::Vector3d::Zero();
    std::vector<Eigen::Vector2d> y;
    for (int k = 0; k < 60; ++k) {
      const double u = k >= delay ? 1.0 : 0.0;
      y.push_back(c * x + d.col(static_cast<Eigen::Index>(i)) * u);
      x = a * x + b.col(static_cast<Eigen::Index>(i)) * u;
    }
    for (std::size_t j = 0; j < 2; ++j) {
      const ChannelModel* ch = find(p, j, i);
      ASSERT_NE(ch, nullptr) << j << i;
      const std::vector<double> s = tf_step(ch->tf, 60);
      for (std::size_t k = 0; k < 60; ++k)
        EXPECT_NEAR(s[k], y[k][static_cast<Eigen::Index>(j)], 1e-10) << j << i << " k " << k;
    }
  }
}

TEST(StateSpace, ContinuousStepResponsesEqualADirectSimulation) {
  const std::string yaml = R"(plant: ssc
sample_time: 0.5
inputs: [u1, u2]
outputs: [y1, y2]
state_space:
  discrete: false
  A: [[-1, 0.5], [-0.3, -0.2]]
  B: [[1, 0], [0.2, 2]]
  C: [[1, 0], [0.5, 1]]
)";
  const PlantModel p = parse_plant(yaml, "ssc.yaml");
  const Eigen::Matrix2d a{{-1, 0.5}, {-0.3, -0.2}};
  const Eigen::Matrix2d b{{1, 0}, {0.2, 2}};
  const Eigen::Matrix2d c{{1, 0}, {0.5, 1}};
  for (Eigen::Index i = 0; i < 2; ++i) {
    // RK4 with the step input held, 1000 steps per sample.
    Eigen::Vector2d x = Eigen::Vector2d::Zero();
    const double h = 0.5 / 1000;
    const auto f = [&](const Eigen::Vector2d& s) -> Eigen::Vector2d { return a * s + b.col(i); };
    std::vector<Eigen::Vector2d> y;
    for (int k = 0; k < 40; ++k) {
      y.push_back(c * x);  // y(k ts): the ZOH model's output at sample k
      for (int n = 0; n < 1000; ++n) {
        const Eigen::Vector2d k1 = f(x), k2 = f(x + h / 2 * k1), k3 = f(x + h / 2 * k2), k4 = f(x + h * k3);
        x += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
      }
    }
    for (std::size_t j = 0; j < 2; ++j) {
      const ChannelModel* ch = find(p, j, static_cast<std::size_t>(i));
      ASSERT_NE(ch, nullptr);
      const std::vector<double> s = tf_step(ch->tf, 40);
      // A step applied at sample 0 reaches the sampled output one sample later.
      EXPECT_NEAR(s[0], 0.0, 1e-12);
      for (std::size_t k = 1; k < 40; ++k)
        EXPECT_NEAR(s[k], y[k][static_cast<Eigen::Index>(j)], 1e-9) << j << i << " k " << k;
    }
  }
}

TEST(StateSpace, TheQuadTankAsAStateSpaceHasTheTransferFunctionFilesChannels) {
  const PlantModel tf = load_plant(MPM_SOURCE_DIR "/config/quad-tank.yaml");
  const PlantModel ss = load_plant(MPM_SOURCE_DIR "/config/quad-tank-state-space.yaml");
  ASSERT_EQ(ss.channels.size(), 4u);
  for (const ChannelModel& want : tf.channels) {
    const ChannelModel* got = find(ss, want.output, want.input);
    ASSERT_NE(got, nullptr);
    // Shared roots cancelled: the first-order channels stay first order.
    ASSERT_EQ(got->tf.den.size(), want.tf.den.size()) << want.output << want.input;
    const std::vector<double> a = tf_step(got->tf, 200), b = tf_step(want.tf, 200);
    for (std::size_t k = 0; k < 200; ++k) EXPECT_NEAR(a[k], b[k], 1e-8 * (1 + std::abs(b[k]))) << k;
  }
}

TEST(StateSpace, TheDisturbanceModelHasTheProcesssSpectrum) {
  const std::string yaml = R"(plant: ssd
sample_time: 1
inputs: [u1]
outputs: [y1, y2]
state_space:
  discrete: true
  A: [[0.95, 0.1], [0, 0.7]]
  B: [[1], [0]]
  C: [[1, 0], [0, 1]]
  G: [[1, 0], [0.5, 1]]
  noise: {w: [0.2, 0.1], v: [0.05, 0.3]}
)";
  const PlantModel p = parse_plant(yaml, "ssd.yaml");
  const Eigen::Matrix2d a{{0.95, 0.1}, {0, 0.7}};
  const Eigen::Matrix2d g{{1, 0}, {0.5, 1}};
  const Eigen::Matrix2d w = Eigen::Vector2d(0.2, 0.1).asDiagonal();
  const double v[] = {0.05, 0.3};
  for (std::size_t j = 0; j < 2; ++j) {
    ASSERT_TRUE(p.noise[j].has_value());
    const NoiseModel& n = *p.noise[j];
    ASSERT_EQ(n.tf.num[0], 1.0);
    for (const double omega : {0.0, 0.1, 0.7, 2.0, 3.1}) {
      const std::complex<double> z = std::polar(1.0, omega);
      // The process: C_j (zI - A)^-1 G w + v_j.
      const Eigen::Matrix2cd resolvent = (z * Eigen::Matrix2cd::Identity() - a.cast<std::complex<double>>()).inverse();
      const Eigen::RowVector2cd h =
          Eigen::RowVector2d::Unit(static_cast<Eigen::Index>(j)).cast<std::complex<double>>() * resolvent *
          g.cast<std::complex<double>>();
      const double process = (h * w.cast<std::complex<double>>() * h.adjoint())(0, 0).real() + v[j];
      // The model: variance |N(z)|^2.
      std::complex<double> num = 0, den = 0;
      for (std::size_t k = 0; k < n.tf.num.size(); ++k) num += n.tf.num[k] * std::pow(z, -static_cast<double>(k));
      for (std::size_t k = 0; k < n.tf.den.size(); ++k) den += n.tf.den[k] * std::pow(z, -static_cast<double>(k));
      EXPECT_NEAR(*n.variance * std::norm(num / den), process, 1e-8 * process) << j << " omega " << omega;
    }
  }
}

TEST(StateSpace, ShapeAndStabilityErrorsAreLocated) {
  const std::string head = "plant: x\nsample_time: 1\ninputs: [u1]\noutputs: [y1]\n";
  struct Case {
    std::string yaml;  // after `head`
    std::string error;  // a part of the message
  };
  const Case cases[] = {
      {"state_space:\n  discrete: true\n  A: [[0.5, 0]]\n  B: [[1]]\n  C: [[1]]\n",
       "bad.yaml:7:7: state_space.A[0]: expected 1 numbers in each row of a 1 x 1 matrix, got 2"},
      {"state_space:\n  discrete: true\n  A: [[0.5]]\n  B: [[1, 2]]\n  C: [[1]]\n",
       "state_space.B[0]: expected 1 numbers in each row"},
      {"state_space:\n  discrete: yes\n  A: [[0.5]]\n  B: [[1]]\n  C: [[1]]\n", "state_space.discrete: expected true"},
      {"state_space:\n  discrete: true\n  A: [[1.5]]\n  B: [[1]]\n  C: [[1]]\n",
       "state_space.A: expected a stable or integrating model"},
      {"model: []\nstate_space:\n  discrete: true\n  A: [[0.5]]\n  B: [[1]]\n  C: [[1]]\n",
       "give the model as `model:` channels or as `state_space:`, not both"},
      {"state_space:\n  discrete: true\n  A: [[0.5]]\n  B: [[1]]\n  C: [[1]]\n  G: [[1]]\n",
       "state_space.noise: missing: G needs noise"},
  };
  for (const Case& c : cases) {
    const std::string e = testing_util::config_error([&] { (void)parse_plant(head + c.yaml, "bad.yaml"); });
    EXPECT_NE(e.find(c.error), std::string::npos) << c.yaml << " -> " << e;
  }
}

}  // namespace
}  // namespace mpm::config
