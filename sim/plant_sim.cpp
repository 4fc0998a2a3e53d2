#include "sim/plant_sim.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>

namespace mpm::sim {

Plant::Plant(std::unique_ptr<Process> process, std::size_t n_controlled, InputStage actuators,
             OutputStage sensors)
    : process_(std::move(process)),
      n_controlled_(n_controlled),
      actuators_(std::move(actuators)),
      sensors_(std::move(sensors)) {
  if (!process_) throw std::invalid_argument("plant: no process");
  if (n_controlled_ > process_->n_inputs())
    throw std::invalid_argument("plant: more controlled inputs than the process has");
  if (actuators_.size() != n_controlled_ || sensors_.size() != process_->n_outputs())
    throw std::invalid_argument("plant: actuators or sensors do not match the process size");
  process_in_.assign(process_->n_inputs(), 0.0);
  process_out_.assign(process_->n_outputs(), 0.0);
}

void Plant::measure(const double* disturbance, double* y) noexcept {
  process_->output(process_out_.data());
  for (std::size_t j = 0; j < process_out_.size(); ++j) process_out_[j] += disturbance[j];
  sensors_.apply(process_out_.data(), y);
}

void Plant::apply(const double* u, const double* extra) noexcept {
  actuators_.apply(u, process_in_.data());
  if (extra != nullptr) std::copy(extra, extra + n_extra(), process_in_.begin() + static_cast<long>(n_controlled_));
  process_->advance(process_in_.data());
}

void Plant::reset() noexcept {
  process_->reset();
  actuators_.reset();
  sensors_.reset();
}

}  // namespace mpm::sim
