// Test data: the Wood-Berry column in open loop, driven by white inputs, with
// the paper's coloured noise N = diag(1/(1-0.8q^-1), 1/(1-0.9q^-1)), one
// sample at a time. The gain of G21 (u1 -> y2) can be changed while running,
// to make a mismatch appear and disappear in one stream. Independent of
// core/ and sim/ on purpose: the tests check the daemon against a plant
// written out here, not against the code under test.
#pragma once

#include <array>
#include <cstdint>
#include <random>

#include "transport/messages.hpp"

namespace mpm::test {

class WoodBerryStream {
 public:
  // Inputs about config/wood-berry.yaml's operating point (15, 12), so the
  // nominal model and the plant start from the same rest; outputs offset (the
  // monitor's intercept must absorb it).
  static constexpr std::array<double, 2> kU0{15.0, 12.0};
  static constexpr std::array<double, 2> kY0{90.0, 5.0};

  explicit WoodBerryStream(std::uint64_t seed, double input_std = 5.0) : rng_(seed), input_std_(input_std) {}

  void set_g21_gain(double factor) { g21_factor_ = factor; }

  // Fills u and y (absolute units) of the next sample.
  void next(double u[2], double y[2]) {
    std::normal_distribution<double> white(0.0, 1.0);
    const double du[2] = {input_std_ * white(rng_), input_std_ * white(rng_)};
    head_ = (head_ + 1) % kHistory;
    hist_[0][head_] = du[0];
    hist_[1][head_] = du[1];
    // Channels b q^-d / (1 + a q^-1), ZOH Wood-Berry (paper Sec. 4.1).
    x11_ = 0.9419 * x11_ + 0.744 * past(0, 2);
    x12_ = 0.9535 * x12_ + -0.8789 * past(1, 4);
    x21_ = 0.9123 * x21_ + 0.5786 * g21_factor_ * past(0, 8);
    x22_ = 0.9329 * x22_ + -1.302 * past(1, 4);
    n1_ = 0.8 * n1_ + white(rng_);
    n2_ = 0.9 * n2_ + white(rng_);
    u[0] = kU0[0] + du[0];
    u[1] = kU0[1] + du[1];
    y[0] = kY0[0] + x11_ + x12_ + n1_;
    y[1] = kY0[1] + x21_ + x22_ + n2_;
  }

  // A complete sample message with the next values.
  void next(msg::Sample& s) {
    s.u.resize(2);
    s.y.resize(2);
    next(s.u.data(), s.y.data());
  }

 private:
  static constexpr std::size_t kHistory = 16;
  double past(std::size_t input, std::size_t delay) const {
    return hist_[input][(head_ + kHistory - delay) % kHistory];
  }

  std::mt19937_64 rng_;
  double input_std_;
  double g21_factor_ = 1.0;
  std::array<std::array<double, kHistory>, 2> hist_{};
  std::size_t head_ = 0;
  double x11_ = 0, x12_ = 0, x21_ = 0, x22_ = 0, n1_ = 0, n2_ = 0;
};

}  // namespace mpm::test
