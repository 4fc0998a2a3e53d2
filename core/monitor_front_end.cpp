#include "core/monitor_front_end.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "core/chi_square.hpp"
#include "core/noise_filter.hpp"

namespace mpm {

// ---- 1. A monitor of a plant ----------------------------------------------

std::vector<std::optional<std::vector<double>>> noise_ar(const PlantModel& plant, int order) {
  std::vector<std::optional<std::vector<double>>> out(plant.n_outputs());
  for (std::size_t j = 0; j < plant.n_outputs(); ++j)
    if (j < plant.noise.size() && plant.noise[j]) out[j] = inverse_noise_ar_coefficients(plant.noise[j]->tf, order);
  return out;
}

std::vector<double> reference_variances(const PlantModel& plant) {
  std::vector<double> out(plant.n_outputs(), 0.0);
  for (std::size_t j = 0; j < plant.n_outputs() && j < plant.noise.size(); ++j)
    if (plant.noise[j] && plant.noise[j]->variance) out[j] = noise_output_variance(plant.noise[j]->tf, *plant.noise[j]->variance);
  return out;
}

std::vector<std::optional<DiscreteTf>> channel_models(const PlantModel& plant) {
  std::vector<std::optional<DiscreteTf>> out(plant.n_outputs() * plant.n_inputs());
  for (const auto& c : plant.channels) out[c.output * plant.n_inputs() + c.input] = c.tf;
  return out;
}

MonitorSettings for_plant(MonitorSettings settings, const PlantModel& plant) {
  if (settings.detector.sample_time <= 0.0 && plant.sample_time > 0.0) settings.detector.sample_time = plant.sample_time;
  return settings;
}

MonitorBlueprint::MonitorBlueprint(const PlantModel& plant, const MonitorSettings& settings, bool plain_lags)
    : inputs_(plant.n_inputs()),
      outputs_(plant.n_outputs()),
      settings_(for_plant(settings, plant)),
      noise_(noise_ar(plant, settings.ar_order)),
      reference_(reference_variances(plant)),
      channels_(plain_lags ? std::vector<std::optional<DiscreteTf>>{} : channel_models(plant)) {}

GrangerMonitor MonitorBlueprint::build(OutputRange outputs, std::size_t front_end_settle) const {
  GrangerMonitor m(inputs_, outputs_, settings_, noise_, reference_, channels_, outputs);
  if (front_end_settle == 0) m.start_settled();
  return m;
}

// ---- 2. The residual front end --------------------------------------------

InputOrigin::InputOrigin(const PlantModel& plant) : u0_(plant.n_inputs(), 0.0) {
  if (plant.operating_point) {
    u0_ = plant.operating_point->inputs;
    known_ = true;
  }
}

bool InputOrigin::offer(const double* u) noexcept {
  if (known_) return true;
  for (std::size_t i = 0; i < u0_.size(); ++i)
    if (!std::isfinite(u[i])) return false;
  std::copy(u, u + u0_.size(), u0_.begin());
  known_ = true;
  return true;
}

std::vector<double> input_origin(const PlantModel& plant, const Eigen::MatrixXd& u) {
  InputOrigin origin(plant);
  // One sample contiguous for offer().
  Eigen::VectorXd row(u.cols());
  for (Eigen::Index k = 0; k < u.rows() && !origin.known(); ++k) {
    row = u.row(k).transpose();
    origin.offer(row.data());
  }
  return origin.u0();
}

Eigen::MatrixXd held_deviations(const Eigen::MatrixXd& u, const std::vector<double>& u0) {
  Eigen::MatrixXd du(u.rows(), u.cols());
  for (Eigen::Index i = 0; i < u.cols(); ++i) {
    double last = u0[static_cast<std::size_t>(i)];
    for (Eigen::Index k = 0; k < u.rows(); ++k) {
      if (std::isfinite(u(k, i))) last = u(k, i);
      du(k, i) = last - u0[static_cast<std::size_t>(i)];
    }
  }
  return du;
}

std::size_t settle_length(const PlantModel& plant, int requested, std::size_t cap, bool all_simulated) {
  if (requested >= 0) return static_cast<std::size_t>(requested);
  if (all_simulated) return 0;
  return settling_samples(plant, 0.01, cap);
}

ResidualFrontEnd::ResidualFrontEnd(const PlantModel& plant, std::size_t settle)
    : origin_(plant),
      initial_origin_(origin_),
      generator_(plant, origin_.u0()),
      at_rest_(generator_),
      use_sim_(plant.n_outputs(), true),
      settle_(static_cast<int>(settle)),
      settling_(settle_) {}

ResidualFrontEnd::ResidualFrontEnd(const PlantModel& plant, const std::vector<double>& u0, std::size_t settle,
                                   std::vector<bool> use_sim)
    : origin_(plant),
      initial_origin_(origin_),
      generator_(plant, u0),
      at_rest_(generator_),
      use_sim_(use_sim.empty() ? std::vector<bool>(plant.n_outputs(), true) : std::move(use_sim)),
      settle_(static_cast<int>(settle)),
      settling_(settle_) {
  if (use_sim_.size() != plant.n_outputs()) throw std::invalid_argument("use_sim: one flag per output");
  origin_.offer(u0.data());  // u0 holds finite values, or the rule's zeros
  origin_.restored();
}

ResidualFrontEnd::Stage ResidualFrontEnd::step(const double* u, const double* y, const double* sim_y,
                                               double* residual) noexcept {
  if (!origin_.known()) {
    if (!origin_.offer(u)) return Stage::kNoOrigin;  // wait for a complete input sample
    generator_.set_origin(origin_.u0().data());
  }
  generator_.step(u, y, residual);
  if (sim_y != nullptr) {
    for (std::size_t j = 0; j < use_sim_.size(); ++j)
      if (use_sim_[j]) residual[j] = y[j] - sim_y[j];
  }
  if (settling_ > 0) {
    --settling_;
    return Stage::kSettling;
  }
  return Stage::kReady;
}

// ---- 3. The locating rule -------------------------------------------------

RecordVerdict record_verdict(const GrangerMonitor& m, double family) {
  RecordVerdict v;
  v.loop_mismatch.assign(m.n_outputs(), false);
  v.by_gamma.assign(m.n_outputs() * m.n_inputs(), false);
  const double limit = m.settings().gamma_lambda * m.settings().gamma_lambda;
  const double level = m.settings().false_alarm / std::max(1.0, family);
  const double raise = m.raise_threshold_at(level);
  const double joint_raise = m.joint_raise_threshold_at(level);
  for (std::size_t j = 0; j < m.n_outputs(); ++j) {
    if (m.loop(j).diverging) {
      v.diverging = true;
      continue;
    }
    bool any = false;
    for (std::size_t i = 0; i < m.n_inputs(); ++i)
      if (m.channel(j, i).lr_conditional > raise) {
        v.located.emplace_back(j, i);
        any = true;
      }
    if (!any && m.loop(j).lr_joint > joint_raise) {
      std::size_t best = m.n_inputs();
      for (std::size_t i = 0; i < m.n_inputs(); ++i)
        if (m.channel(j, i).gamma < limit &&
            (best == m.n_inputs() || m.channel(j, i).f_pairwise > m.channel(j, best).f_pairwise))
          best = i;
      if (best < m.n_inputs()) {
        v.located.emplace_back(j, best);
        v.by_gamma[j * m.n_inputs() + best] = true;
      }
    }
    v.loop_mismatch[j] = any || m.loop(j).lr_joint > joint_raise;
  }
  return v;
}

double record_test_count(const GrangerMonitor& m) noexcept {
  return static_cast<double>(m.n_outputs() * (m.n_inputs() + 1));
}

AlarmFacts alarm_facts(const GrangerMonitor& m, std::size_t output, std::size_t input) noexcept {
  const ChannelStats& c = m.channel(output, input);
  const LoopStats& l = m.loop(output);
  AlarmFacts f;
  f.raised = c.alarm;
  f.statistic = l.score;
  f.threshold = l.score_threshold;
  f.window = l.score_window;
  f.f_conditional = c.f_conditional;
  f.conditional_score = c.score_conditional;
  // A raise is the sequential detector's: its p-value is that of the
  // channel's conditional score (nb dof). A clear reports the channel's
  // current conditional LR.
  f.p_value = c.alarm ? chi_square_survival(c.score_conditional, static_cast<double>(m.settings().input_order))
                      : m.p_value(c.lr_conditional);
  f.gamma = c.gamma;
  f.by_gamma = c.located_by_gamma;
  return f;
}

}  // namespace mpm
