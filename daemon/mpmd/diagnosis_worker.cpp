#include "daemon/mpmd/diagnosis_worker.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <limits>

#include "core/diagnosis.hpp"
#include "daemon/mpmd/log.hpp"
#include "daemon/offline.hpp"

namespace mpm {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string channel_text(const PlantModel& plant, const diagnosis::Channel& c) {
  return (c.input ? plant.inputs[*c.input] : std::string("(no input)")) + " -> " + plant.outputs[c.output];
}

// The finding that explains the raised output best: one on the raised
// channel, else one on the raised output, else none.
const diagnosis::Finding* finding_for(const diagnosis::Result& result, std::size_t output, std::size_t input) {
  const diagnosis::Finding* on_output = nullptr;
  for (const auto& f : result.findings) {
    for (const auto& c : f.channels) {
      if (c.output != output) continue;
      if (c.input && *c.input == input) return &f;
      if (on_output == nullptr) on_output = &f;
    }
  }
  return on_output;
}

}  // namespace

DiagnosisWorker::DiagnosisWorker(const PlantModel& plant, std::size_t window)
    : plant_(plant),
      nominal_(channel_models(plant)),
      window_(window),
      ring_(Eigen::MatrixXd::Constant(static_cast<Eigen::Index>(window), static_cast<Eigen::Index>(plant.n_inputs() + plant.n_outputs()), kNaN)),
      snapshot_(ring_.rows(), ring_.cols()) {}

DiagnosisWorker::~DiagnosisWorker() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void DiagnosisWorker::record(const double* u, const double* residual) noexcept {
  if (window_ == 0) return;
  const auto row = static_cast<Eigen::Index>(head_);
  const std::size_t m = plant_.n_inputs();
  for (std::size_t i = 0; i < m; ++i) ring_(row, static_cast<Eigen::Index>(i)) = u[i];
  for (std::size_t j = 0; j < plant_.n_outputs(); ++j) ring_(row, static_cast<Eigen::Index>(m + j)) = residual[j];
  head_ = head_ + 1 == window_ ? 0 : head_ + 1;
  if (filled_ < window_) ++filled_;
}

bool DiagnosisWorker::request(Request r) {
  std::lock_guard lock(mutex_);
  if (!thread_.joinable()) thread_ = std::thread([this] { run(); });
  if (busy_) {
    ++coalesced_;
    const bool replaced = pending_.has_value();
    pending_ = std::move(r);
    return !replaced;
  }
  submit_locked(r);
  return true;
}

void DiagnosisWorker::submit_locked(const Request& r) {
  // Oldest first: rows head_.. then 0..head_ (when the ring has wrapped).
  const auto n = static_cast<Eigen::Index>(filled_);
  const auto start = static_cast<Eigen::Index>(filled_ < window_ ? 0 : head_);
  for (Eigen::Index k = 0; k < n; ++k) snapshot_.row(k) = ring_.row((start + k) % static_cast<Eigen::Index>(window_));
  snapshot_rows_ = filled_;
  job_ = r;
  busy_ = true;
  wake_.notify_all();
}

bool DiagnosisWorker::take(msg::Diagnosis& out) {
  std::lock_guard lock(mutex_);
  if (!busy_ && pending_) {
    submit_locked(*pending_);
    pending_.reset();
  }
  if (!result_) return false;
  out = std::move(*result_);
  result_.reset();
  return true;
}

void DiagnosisWorker::run() {
  const auto m = static_cast<Eigen::Index>(plant_.n_inputs());
  const auto p = static_cast<Eigen::Index>(plant_.n_outputs());
  for (;;) {
    Request r;
    Eigen::MatrixXd u, residual;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [&] { return stop_ || job_.has_value(); });
      if (stop_) return;
      r = std::move(*job_);
      job_.reset();
      const auto n = static_cast<Eigen::Index>(snapshot_rows_);
      u = snapshot_.topLeftCorner(n, m);
      residual = snapshot_.block(0, m, n, p);
    }
    msg::Diagnosis d;
    const auto started = std::chrono::steady_clock::now();
    try {
      d = diagnose(plant_, nominal_, u, residual, r);
    } catch (const std::exception& e) {  // a bad window must not end the service
      d.controller_id = r.controller_id;
      d.output = plant_.outputs[r.output];
      d.input = plant_.inputs[r.input];
      d.text = std::string("diagnosis failed: ") + e.what();
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    log::write(log::Level::kNotice, "controller '%s': diagnosis of %s -> %s over %d samples (%.2f s): %s",
               d.controller_id.c_str(), d.input.c_str(), d.output.c_str(), d.window, seconds, d.text.c_str());
    std::lock_guard lock(mutex_);
    result_ = std::move(d);
    busy_ = false;
    completed_.fetch_add(1);
  }
}

msg::Diagnosis DiagnosisWorker::diagnose(const PlantModel& plant, const std::vector<std::optional<DiscreteTf>>& nominal,
                                         const Eigen::MatrixXd& u, const Eigen::MatrixXd& residual,
                                         const Request& r) {
  msg::Diagnosis d;
  d.controller_id = r.controller_id;
  d.utime = r.utime;
  d.sample_sequence = r.seq;
  d.output = plant.outputs[r.output];
  d.input = plant.inputs[r.input];
  d.output_index = static_cast<std::int32_t>(r.output);
  d.input_index = static_cast<std::int32_t>(r.input);
  d.window = static_cast<std::int32_t>(u.rows());

  // The problem `mpm diagnose` builds from a recording (daemon/offline.hpp),
  // from the window, by the same front end (u0 = the operating point, else
  // the window's first complete input sample; missing inputs hold their
  // last value).
  diagnosis::Problem problem = plant_problem(plant, u, residual);
  problem.nominal = nominal;  // computed once, at setup
  problem.monitor_flag.assign(plant.n_outputs(), false);
  problem.monitor_flag[r.output] = true;
  problem.monitor_located.resize(plant.n_outputs());
  problem.monitor_located[r.output].push_back(r.input);

  const diagnosis::Result result = diagnosis::diagnose(problem);
  const diagnosis::Finding* f = finding_for(result, r.output, r.input);
  if (f == nullptr) {
    d.text = "no physics hypothesis explains " + d.input + " -> " + d.output + " in the last " +
             std::to_string(d.window) + " samples" +
             (result.findings.empty() ? std::string() : " (findings elsewhere: " + result.findings.front().physics + ")");
    return d;
  }
  d.found = true;
  d.physics = f->physics;
  for (std::size_t c = 0; c < f->channels.size(); ++c) {
    d.channels += (c ? ", " : "") + channel_text(plant, f->channels[c]);
  }
  if (f->nominal && f->fitted) {
    const double g0 = f->nominal->dc_gain(), g1 = f->fitted->dc_gain();
    if (std::isfinite(g0) && std::isfinite(g1) && g0 != 0.0) {
      d.parameter_names.push_back("gain_ratio");
      d.parameter_values.push_back(g1 / g0);
    }
    d.parameter_names.push_back("delay_change");
    d.parameter_values.push_back(f->fitted->delay - f->nominal->delay);
  }
  for (const auto& [name, value] : f->parameters) {
    d.parameter_names.push_back(name);
    d.parameter_values.push_back(value);
  }
  const double before = f->fit.holdout_variance_before, after = f->fit.holdout_variance_after;
  d.holdout_improvement = before > 0.0 ? 1.0 - after / before : 0.0;
  char tail[96];
  std::snprintf(tail, sizeof tail, " (held-out prediction error %.1f %% lower)", 100.0 * d.holdout_improvement);
  d.text = f->summary + tail;
  return d;
}

}  // namespace mpm
