#include "sim/linear_process.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>
#include <utility>

namespace mpm::sim {

std::size_t index_of(const std::vector<std::string>& names, const std::string& name, const char* what) {
  const auto it = std::find(names.begin(), names.end(), name);
  if (it == names.end()) throw std::invalid_argument(std::string("unknown ") + what + " '" + name + "'");
  return static_cast<std::size_t>(it - names.begin());
}

namespace {

}  // namespace

DiscreteTf one_sample_ahead(const DiscreteTf& tf) {
  DiscreteTf out = tf;
  if (out.delay > 0) {
    --out.delay;
  } else if (out.num.size() > 1 && out.num[0] == 0.0) {
    out.num.erase(out.num.begin());
  } else if (!out.is_zero()) {
    throw std::invalid_argument("the channel has direct feedthrough (delay 0 and num[0] != 0): "
                                "a sampled plant needs at least one sample of delay");
  }
  return out;
}

std::vector<LinearChannel> plant_channels(const PlantModel& model, const std::vector<ChannelEdit>& edits) {
  std::vector<LinearChannel> out;
  for (const auto& c : model.channels) out.push_back({c.output, c.input, c.tf, 0.0});
  std::set<std::pair<std::size_t, std::size_t>> edited;
  for (const auto& e : edits) {
    const std::size_t j = index_of(model.outputs, e.output, "output");
    const std::size_t i = index_of(model.inputs, e.input, "input");
    if (!edited.insert({j, i}).second)
      throw std::invalid_argument("channel " + e.output + " <- " + e.input + " is edited twice");
    DiscreteTf tf = edited_channel(model.channel(j, i), e, model.sample_time);
    const auto it = std::find_if(out.begin(), out.end(),
                                 [&](const LinearChannel& c) { return c.output == j && c.input == i; });
    if (it != out.end()) {
      it->tf = std::move(tf);
      it->soft_saturation = e.soft_saturation;
    } else {
      out.push_back({j, i, std::move(tf), e.soft_saturation});
    }
  }
  return out;
}

LinearProcess::LinearProcess(std::size_t n_inputs, std::size_t n_outputs,
                             const std::vector<LinearChannel>& channels)
    : n_inputs_(n_inputs), next_y_(n_outputs, 0.0) {
  for (const auto& c : channels) {
    if (c.output >= n_outputs || c.input >= n_inputs)
      throw std::invalid_argument("linear plant: channel index out of range");
    if (c.tf.is_zero()) continue;
    try {
      channels_.push_back({c.output, c.input, DiscreteFilter(one_sample_ahead(c.tf)), c.soft_saturation});
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("plant channel (output " + std::to_string(c.output + 1) + ", input " +
                                  std::to_string(c.input + 1) + "): " + e.what());
    }
  }
}

void LinearProcess::output(double* y) const noexcept { std::copy(next_y_.begin(), next_y_.end(), y); }

void LinearProcess::advance(const double* u) noexcept {
  std::fill(next_y_.begin(), next_y_.end(), 0.0);
  for (auto& c : channels_) {
    const double v = u[c.input];
    next_y_[c.output] += c.one_ahead.step(v / (1.0 + c.soft_saturation * std::abs(v)));
  }
}

void LinearProcess::reset() noexcept {
  for (auto& c : channels_) c.one_ahead.reset(0.0);
  std::fill(next_y_.begin(), next_y_.end(), 0.0);
}

}  // namespace mpm::sim
