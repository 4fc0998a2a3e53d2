#include "sim/closed_loop.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>

namespace mpm::sim {
namespace {

OperatingPoint model_operating_point(const PlantModel& m) {
  if (m.operating_point) return *m.operating_point;
  return {std::vector<double>(m.n_inputs(), 0.0), std::vector<double>(m.n_outputs(), 0.0)};
}

std::vector<SetpointSpec> setpoint_specs(const PlantModel& m, const LoopConfig& c) {
  if (c.setpoints.empty()) return std::vector<SetpointSpec>(m.n_outputs());
  if (c.setpoints.size() != m.n_outputs())
    throw std::invalid_argument("setpoints: " + std::to_string(c.setpoints.size()) + " given for " +
                                std::to_string(m.n_outputs()) + " outputs");
  return c.setpoints;
}

std::vector<std::string> recording_columns(const PlantModel& m, const LoopConfig& c) {
  std::vector<std::string> names{"t"};
  names.insert(names.end(), m.inputs.begin(), m.inputs.end());
  names.insert(names.end(), m.outputs.begin(), m.outputs.end());
  for (const auto& y : m.outputs) names.push_back("r_" + y);
  for (const auto& x : c.plant.extra_inputs)
    if (x.recorded) names.push_back(x.name);
  return names;
}

}  // namespace

ClosedLoop::ClosedLoop(const PlantModel& model, const LoopConfig& config, std::uint64_t seed,
                       const PlantModel* reference)
    : model_(model),
      model_op_(model_operating_point(model)),
      plant_op_(plant_operating_point(model, config.plant)),
      plant_(build_plant(model, config.plant)),
      mpc_(model, config.mpc),
      noise_(noise_channels(model, config.default_noise_variance), seed, config.noise_scale),
      setpoints_(setpoint_specs(model, config), model.sample_time, seed),
      extra_source_(config.plant.extra_inputs, seed),
      columns_(recording_columns(model, config)) {
  const std::size_t ni = model.n_inputs(), no = model.n_outputs(), nx = config.plant.extra_inputs.size();
  if (model_op_.inputs.size() != ni || model_op_.outputs.size() != no)
    throw std::invalid_argument("operating point sizes do not match the model");
  if (config.warmup < 0) throw std::invalid_argument("warmup must be >= 0 samples");
  for (std::size_t x = 0; x < nx; ++x) {
    extra_op_.push_back(config.plant.extra_inputs[x].operating_value);
    if (config.plant.extra_inputs[x].recorded) recorded_extra_.push_back(x);
  }
  r_dev_.assign(no, 0.0);
  d_.assign(no, 0.0);
  y_plant_.assign(no, 0.0);
  y_ctrl_.assign(no, 0.0);
  u_ctrl_.assign(ni, 0.0);
  u_plant_.assign(ni, 0.0);
  extra_dev_.assign(nx, 0.0);
  u_abs_.assign(ni, 0.0);
  y_abs_.assign(no, 0.0);
  r_abs_.assign(no, 0.0);
  extra_abs_.assign(recorded_extra_.size(), 0.0);
  sample_.u = u_abs_;
  sample_.y = y_abs_;
  sample_.r = r_abs_;
  sample_.extra = extra_abs_;
  if (reference) {
    if (reference->inputs != model.inputs || reference->outputs != model.outputs)
      throw std::invalid_argument("the reference model's inputs and outputs differ from the model's");
    const PlantSpec unedited;
    reference_.emplace(Reference{plant_operating_point(*reference, unedited), build_plant(*reference, unedited),
                                 NoiseSource(noise_channels(*reference, config.default_noise_variance), seed,
                                             config.noise_scale),
                                 std::vector<double>(no), std::vector<double>(no), std::vector<double>(ni),
                                 std::vector<double>(no)});
    sample_.reference = reference_->y_abs;
  }
  k_ = -config.warmup;
  while (k_ < 0) step();
}

// The controller works in deviations from the model's operating point, the
// plant in deviations from its own; absolute values connect the two.
const LoopSample& ClosedLoop::step() noexcept {
  setpoints_.at(k_, r_dev_.data());
  noise_.draw(d_.data());
  plant_.measure(d_.data(), y_plant_.data());
  if (reference_) {
    Reference& ref = *reference_;
    ref.noise.draw(ref.d.data());
    ref.plant.measure(ref.d.data(), ref.y_dev.data());
    for (std::size_t j = 0; j < ref.y_abs.size(); ++j) ref.y_abs[j] = ref.op.outputs[j] + ref.y_dev[j];
  }
  for (std::size_t j = 0; j < y_abs_.size(); ++j) {
    y_abs_[j] = plant_op_.outputs[j] + y_plant_[j];
    y_ctrl_[j] = y_abs_[j] - model_op_.outputs[j];
    r_abs_[j] = model_op_.outputs[j] + r_dev_[j];
  }
  mpc_.step(y_ctrl_.data(), r_dev_.data(), u_ctrl_.data());
  for (std::size_t l = 0; l < u_abs_.size(); ++l) {
    u_abs_[l] = model_op_.inputs[l] + u_ctrl_[l];
    u_plant_[l] = u_abs_[l] - plant_op_.inputs[l];
  }
  extra_source_.draw(extra_dev_.data());
  for (std::size_t i = 0; i < recorded_extra_.size(); ++i) {
    const std::size_t x = recorded_extra_[i];
    extra_abs_[i] = extra_op_[x] + extra_dev_[x];
  }
  plant_.apply(u_plant_.data(), extra_dev_.empty() ? nullptr : extra_dev_.data());
  if (reference_) {
    Reference& ref = *reference_;
    for (std::size_t l = 0; l < ref.u_dev.size(); ++l) ref.u_dev[l] = u_abs_[l] - ref.op.inputs[l];
    ref.plant.apply(ref.u_dev.data(), nullptr);
  }
  sample_.k = k_;
  sample_.t = static_cast<double>(k_) * model_.sample_time;
  ++k_;
  return sample_;
}

void ClosedLoop::fill_row(const LoopSample& s, double* row) const noexcept {
  *row++ = s.t;
  for (auto* part : {&s.u, &s.y, &s.r, &s.extra}) row = std::copy(part->begin(), part->end(), row);
}

config::Recording simulate(ClosedLoop& loop, std::size_t samples, const std::string& recording_name,
                           config::Recording* reference) {
  if (reference && !loop.has_reference()) throw std::invalid_argument("the loop has no reference model");
  config::Recording rec;
  rec.source = recording_name;
  rec.names = loop.column_names();
  rec.data.resize(static_cast<Eigen::Index>(samples), static_cast<Eigen::Index>(rec.names.size()));
  if (reference) {
    reference->source = recording_name + " (reference model)";
    reference->names = {"t"};
    const auto& outputs = loop.model().outputs;
    reference->names.insert(reference->names.end(), outputs.begin(), outputs.end());
    reference->data.resize(static_cast<Eigen::Index>(samples), static_cast<Eigen::Index>(reference->names.size()));
  }
  std::vector<double> row(rec.names.size());
  for (std::size_t k = 0; k < samples; ++k) {
    const LoopSample& s = loop.step();
    loop.fill_row(s, row.data());
    const auto r = static_cast<Eigen::Index>(k);
    for (std::size_t c = 0; c < row.size(); ++c) rec.data(r, static_cast<Eigen::Index>(c)) = row[c];
    if (reference) {
      reference->data(r, 0) = s.t;
      for (std::size_t j = 0; j < s.reference.size(); ++j)
        reference->data(r, static_cast<Eigen::Index>(j + 1)) = s.reference[j];
    }
  }
  return rec;
}

}  // namespace mpm::sim
