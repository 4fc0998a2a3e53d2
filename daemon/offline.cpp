#include "daemon/offline.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <thread>

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

MonitorSettings for_plant(MonitorSettings settings, const PlantModel& plant) {
  if (settings.detector.sample_time <= 0.0 && plant.sample_time > 0.0) settings.detector.sample_time = plant.sample_time;
  return settings;
}

MonitorPartFactory monitor_factory(const PlantModel& plant, const MonitorSettings& settings, bool plain_lags) {
  return [m = plant.n_inputs(), n = plant.n_outputs(), settings = for_plant(settings, plant), noise = noise_ar(plant, settings.ar_order),
          reference = reference_variances(plant),
          channels = plain_lags ? std::vector<std::optional<DiscreteTf>>{} : channel_models(plant)](OutputRange outputs) {
    return GrangerMonitor(m, n, settings, noise, reference, channels, outputs);
  };
}

std::size_t replay_threads(std::size_t outputs) {
  const std::size_t cores = std::max<std::size_t>(1, std::thread::hardware_concurrency());
  return std::max<std::size_t>(1, std::min(cores, outputs));
}

void run_monitor_parallel(GrangerMonitor& monitor, const double* u, const double* residual, std::size_t first,
                          std::size_t samples, std::size_t threads, const MonitorPartFactory& make_part,
                          const PartSampleCallback& on_sample) {
  const std::size_t m = monitor.n_inputs();
  const std::size_t p = monitor.n_outputs();
  threads = std::max<std::size_t>(1, std::min(threads, p));
  // Contiguous parts of nearly equal size; built here, so a factory that
  // throws does so before any thread starts.
  std::vector<GrangerMonitor> parts;
  parts.reserve(threads);
  for (std::size_t t = 0, begin = 0; t < threads; ++t) {
    const std::size_t count = p / threads + (t < p % threads ? 1 : 0);
    parts.push_back(make_part(OutputRange{begin, count}));
    begin += count;
  }
  const auto run_part = [&](GrangerMonitor& part) {
    for (std::size_t k = first; k < samples; ++k) {
      part.update(u + k * m, residual + k * p);
      if (on_sample) on_sample(k, part);
    }
  };
  if (threads == 1) {
    run_part(parts[0]);
  } else {
    std::vector<std::thread> workers;
    workers.reserve(threads - 1);
    for (std::size_t t = 1; t < threads; ++t) workers.emplace_back(run_part, std::ref(parts[t]));
    run_part(parts[0]);
    for (std::thread& w : workers) w.join();
  }
  for (const GrangerMonitor& part : parts) monitor.adopt_outputs(part);
}

void run_monitor_parallel(GrangerMonitor& monitor, const ResidualSeries& s, std::size_t threads,
                          const MonitorPartFactory& make_part, const PartSampleCallback& on_sample) {
  // One sample contiguous, for every thread to read.
  const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> u = s.u;
  const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> d = s.residual;
  run_monitor_parallel(monitor, u.data(), d.data(), s.transient, static_cast<std::size_t>(s.u.rows()), threads,
                       make_part, on_sample);
}

GrangerMonitor monitor_record(const PlantModel& plant, const ResidualSeries& s, const MonitorSettings& settings,
                              std::size_t threads, bool plain_lags, const PartSampleCallback& on_sample) {
  const MonitorPartFactory make = monitor_factory(plant, settings, plain_lags);
  GrangerMonitor monitor = make(OutputRange{});
  run_monitor_parallel(monitor, s, threads, make, on_sample);
  return monitor;
}

diagnosis::Problem diagnosis_problem(const PlantModel& plant, const config::Recording& rec,
                                     const config::BoundRecording& bound, const ResidualSeries& series,
                                     const RecordVerdict& verdict) {
  diagnosis::Problem p;
  p.inputs = plant.inputs;
  p.outputs = plant.outputs;
  p.sample_time = plant.sample_time;
  const Eigen::Index n = series.u.rows(), m = series.u.cols();
  // Deviation inputs as the residual generator sees them: u - u0, holding the
  // last good value over missing samples.
  std::vector<double> u0(static_cast<std::size_t>(m), 0.0);
  if (plant.operating_point) {
    u0 = plant.operating_point->inputs;
  } else {
    for (Eigen::Index k = 0; k < n; ++k)
      if (series.u.row(k).allFinite()) {
        for (Eigen::Index i = 0; i < m; ++i) u0[static_cast<std::size_t>(i)] = series.u(k, i);
        break;
      }
  }
  p.u_abs = series.u;
  p.du.resize(n, m);
  for (Eigen::Index i = 0; i < m; ++i) {
    double last = u0[static_cast<std::size_t>(i)];
    for (Eigen::Index k = 0; k < n; ++k) {
      if (std::isfinite(series.u(k, i))) last = series.u(k, i);
      p.du(k, i) = last - u0[static_cast<std::size_t>(i)];
    }
  }
  p.residual = series.residual;
  p.begin = series.transient;
  for (std::size_t c : bound.extra) p.extra_names.push_back(rec.names[c]);
  p.extra.resize(n, static_cast<Eigen::Index>(bound.extra.size()));
  for (std::size_t c = 0; c < bound.extra.size(); ++c)
    p.extra.col(static_cast<Eigen::Index>(c)) = rec.data.col(static_cast<Eigen::Index>(bound.extra[c]));
  p.nominal = channel_models(plant);
  p.noise.resize(plant.n_outputs());
  p.noise_variance.resize(plant.n_outputs());
  for (std::size_t j = 0; j < plant.n_outputs() && j < plant.noise.size(); ++j)
    if (plant.noise[j]) {
      p.noise[j] = plant.noise[j]->tf;
      p.noise_variance[j] = plant.noise[j]->variance;
    }
  p.monitor_flag = verdict.loop_mismatch;
  p.monitor_located.resize(plant.n_outputs());
  for (const auto& [j, i] : verdict.located) p.monitor_located[j].push_back(i);
  return p;
}

}  // namespace mpm
