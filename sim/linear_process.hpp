// A linear plant: the nominal model's channels with mismatch edits applied.
#pragma once

#include <string>
#include <vector>

#include "core/plant_model.hpp"
#include "core/transfer_function.hpp"
#include "sim/channel_edit.hpp"
#include "sim/process.hpp"

namespace mpm::sim {

struct LinearChannel {
  std::size_t output = 0;
  std::size_t input = 0;
  DiscreteTf tf;  // y_output(k) += tf u_input(k); must be strictly proper
  double soft_saturation = 0.0;  // tf acts on u / (1 + a |u|) (ChannelEdit::soft_saturation)
};

// The position of `name` in `names`; throws std::invalid_argument "unknown
// <what> '<name>'" when it is not there (an edit naming a signal the plant
// does not have).
std::size_t index_of(const std::vector<std::string>& names, const std::string& name, const char* what);

// The model's channels with `edits` applied (matched by output/input name).
// Edits naming unknown signals, or editing one channel twice, throw
// std::invalid_argument.
std::vector<LinearChannel> plant_channels(const PlantModel& model, const std::vector<ChannelEdit>& edits);

class LinearProcess final : public Process {
 public:
  // Throws std::invalid_argument if a channel has direct feedthrough (the
  // output at k would depend on the input chosen from it).
  LinearProcess(std::size_t n_inputs, std::size_t n_outputs, const std::vector<LinearChannel>& channels);

  std::size_t n_inputs() const noexcept override { return n_inputs_; }
  std::size_t n_outputs() const noexcept override { return next_y_.size(); }
  void output(double* y) const noexcept override;
  void advance(const double* u) noexcept override;
  void reset() noexcept override;

 private:
  struct Channel {
    std::size_t output;
    std::size_t input;
    DiscreteFilter one_ahead;  // tf with one sample of delay taken out: fed u(k), gives y(k+1)
    double soft_saturation;
  };
  std::size_t n_inputs_ = 0;
  std::vector<Channel> channels_;
  std::vector<double> next_y_;  // y at the current sample
};

// tf = q^-1 * result; throws std::invalid_argument if tf has direct feedthrough.
DiscreteTf one_sample_ahead(const DiscreteTf& tf);

}  // namespace mpm::sim
