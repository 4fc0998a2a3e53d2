#include "daemon/offline.hpp"

#include <cmath>

#include "core/mimo_model.hpp"
#include "core/noise_filter.hpp"

namespace mpm {

ResidualSeries compute_residuals(const PlantModel& plant, const config::Recording& rec,
                                 const config::BoundRecording& bound) {
  const auto n = static_cast<Eigen::Index>(rec.samples());
  const auto m = static_cast<Eigen::Index>(plant.n_inputs());
  const auto p = static_cast<Eigen::Index>(plant.n_outputs());
  ResidualSeries s;
  s.u.resize(n, m);
  s.residual.resize(n, p);
  for (Eigen::Index i = 0; i < m; ++i) s.u.col(i) = rec.data.col(static_cast<Eigen::Index>(bound.inputs[static_cast<std::size_t>(i)]));

  std::vector<double> u0(plant.n_inputs(), 0.0);
  if (plant.operating_point) {
    u0 = plant.operating_point->inputs;
  } else {
    for (Eigen::Index k = 0; k < n; ++k)
      if (s.u.row(k).allFinite()) {
        for (Eigen::Index i = 0; i < m; ++i) u0[static_cast<std::size_t>(i)] = s.u(k, i);
        break;
      }
  }
  ResidualGenerator gen(plant, u0);
  std::vector<double> y(plant.n_outputs()), r(plant.n_outputs());
  bool all_sim = true;
  for (Eigen::Index k = 0; k < n; ++k) {
    const Eigen::VectorXd u = s.u.row(k).transpose();
    for (Eigen::Index j = 0; j < p; ++j) y[static_cast<std::size_t>(j)] = rec.data(k, static_cast<Eigen::Index>(bound.outputs[static_cast<std::size_t>(j)]));
    gen.step(u.data(), y.data(), r.data());
    for (Eigen::Index j = 0; j < p; ++j) {
      const auto& sim = bound.sim[static_cast<std::size_t>(j)];
      s.residual(k, j) = sim ? y[static_cast<std::size_t>(j)] - rec.data(k, static_cast<Eigen::Index>(*sim)) : r[static_cast<std::size_t>(j)];
    }
  }
  for (std::size_t j = 0; j < plant.n_outputs(); ++j) {
    s.from_simulation.push_back(bound.sim[j].has_value());
    all_sim = all_sim && bound.sim[j].has_value();
  }
  // The user's simulation already accounts for the past; our model started
  // from rest needs its transient discarded (at most a tenth of the record).
  s.transient = all_sim ? 0 : settling_samples(plant, 0.01, static_cast<std::size_t>(n / 10));
  return s;
}

std::vector<std::optional<std::vector<double>>> noise_ar(const PlantModel& plant, int order) {
  std::vector<std::optional<std::vector<double>>> out(plant.n_outputs());
  for (std::size_t j = 0; j < plant.n_outputs(); ++j)
    if (j < plant.noise.size() && plant.noise[j]) out[j] = inverse_noise_ar_coefficients(plant.noise[j]->tf, order);
  return out;
}

RecordVerdict record_verdict(const GrangerMonitor& m) {
  RecordVerdict v;
  v.loop_mismatch.assign(m.n_outputs(), false);
  v.by_gamma.assign(m.n_outputs() * m.n_inputs(), false);
  const double limit = m.settings().gamma_lambda * m.settings().gamma_lambda;
  for (std::size_t j = 0; j < m.n_outputs(); ++j) {
    if (m.loop(j).diverging) {
      v.diverging = true;
      continue;
    }
    bool any = false;
    for (std::size_t i = 0; i < m.n_inputs(); ++i)
      if (m.channel(j, i).lr_conditional > m.raise_threshold()) {
        v.located.emplace_back(j, i);
        any = true;
      }
    if (!any && m.loop(j).lr_joint > m.joint_raise_threshold()) {
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
    v.loop_mismatch[j] = any || m.loop(j).lr_joint > m.joint_raise_threshold();
  }
  return v;
}

std::vector<std::optional<DiscreteTf>> channel_models(const PlantModel& plant) {
  std::vector<std::optional<DiscreteTf>> out(plant.n_outputs() * plant.n_inputs());
  for (const auto& c : plant.channels) out[c.output * plant.n_inputs() + c.input] = c.tf;
  return out;
}

std::vector<double> reference_variances(const PlantModel& plant) {
  std::vector<double> out(plant.n_outputs(), 0.0);
  for (std::size_t j = 0; j < plant.n_outputs() && j < plant.noise.size(); ++j)
    if (plant.noise[j] && plant.noise[j]->variance) out[j] = noise_output_variance(plant.noise[j]->tf, *plant.noise[j]->variance);
  return out;
}

}  // namespace mpm
