#include "core/mimo_model.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace mpm {

MimoModel::MimoModel(const PlantModel& plant)
    : n_inputs_(plant.n_inputs()), n_outputs_(plant.n_outputs()) {
  for (const auto& c : plant.channels) {
    if (c.output >= n_outputs_ || c.input >= n_inputs_)
      throw std::invalid_argument("channel index out of range");
    if (c.tf.is_zero()) continue;  // explicit zero: nothing to step
    channels_.push_back({c.output, c.input, DiscreteFilter(c.tf)});
  }
}

void MimoModel::step(const double* u, double* y) noexcept {
  std::fill(y, y + n_outputs_, 0.0);
  for (auto& c : channels_) y[c.output] += c.filter.step(u[c.input]);
}

void MimoModel::reset() noexcept {
  for (auto& c : channels_) c.filter.reset(0.0);
}

ResidualGenerator::ResidualGenerator(const PlantModel& plant, std::vector<double> input_operating_point)
    : model_(plant),
      u0_(std::move(input_operating_point)),
      du_(plant.n_inputs(), 0.0),
      y_model_(plant.n_outputs(), 0.0),
      last_good_u_(plant.n_inputs(), 0.0) {
  if (u0_.size() != plant.n_inputs()) throw std::invalid_argument("operating point size != number of inputs");
  last_good_u_ = u0_;
}

void ResidualGenerator::step(const double* u, const double* y, double* residual) noexcept {
  bool input_missing = false;
  for (std::size_t i = 0; i < du_.size(); ++i) {
    if (std::isfinite(u[i])) {
      last_good_u_[i] = u[i];
    } else {
      input_missing = true;
    }
    du_[i] = last_good_u_[i] - u0_[i];
  }
  model_.step(du_.data(), y_model_.data());
  for (std::size_t j = 0; j < y_model_.size(); ++j)
    residual[j] = input_missing ? NAN : y[j] - y_model_[j];
}

void ResidualGenerator::set_origin(const double* u0) noexcept {
  std::copy(u0, u0 + u0_.size(), u0_.begin());
  last_good_u_ = u0_;
}

}  // namespace mpm

namespace mpm {

std::size_t settling_samples(const PlantModel& plant, double fraction, std::size_t cap) {
  std::size_t worst = 0;
  for (const auto& c : plant.channels) {
    if (c.tf.is_zero()) continue;
    double slowest = 0.0;
    for (double m : root_magnitudes(c.tf.den)) slowest = std::max(slowest, m);
    if (slowest >= 1.0) return cap;
    std::size_t n = static_cast<std::size_t>(c.tf.delay) + c.tf.num.size();
    if (slowest > 0.0) n += static_cast<std::size_t>(std::ceil(std::log(fraction) / std::log(slowest)));
    worst = std::max(worst, n);
  }
  return std::min(worst, cap);
}

}  // namespace mpm

namespace mpm {

double dominant_pole(const PlantModel& plant, double cap) {
  double slowest = 0.0;
  for (const auto& c : plant.channels) {
    if (c.tf.is_zero()) continue;
    for (double m : root_magnitudes(c.tf.den))
      if (m < 1.0 - 1e-9) slowest = std::max(slowest, m);
  }
  return std::min(slowest, cap);
}

}  // namespace mpm
