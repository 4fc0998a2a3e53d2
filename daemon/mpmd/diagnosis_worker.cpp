#include "daemon/mpmd/diagnosis_worker.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <limits>

#include "core/diagnosis.hpp"
#include "daemon/mpmd/log.hpp"
#include "daemon/offline.hpp"
#include "daemon/scan_look.hpp"

namespace mpm {

DiagnosisWorker::DiagnosisWorker(const PlantModel& plant, std::size_t window)
    : plant_(plant),
      nominal_(channel_models(plant)),
      window_(window),
      ring_(window, plant.n_inputs(), plant.n_outputs()),
      snapshot_(static_cast<Eigen::Index>(window), static_cast<Eigen::Index>(plant.n_inputs() + plant.n_outputs())) {}

DiagnosisWorker::~DiagnosisWorker() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void DiagnosisWorker::record(const double* u, const double* residual) noexcept { ring_.record(u, residual); }

void DiagnosisWorker::start_locked() {
  if (!thread_.joinable()) thread_ = std::thread([this] { run(); });
}

bool DiagnosisWorker::request(Request r) {
  std::lock_guard lock(mutex_);
  start_locked();
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
  ring_.copy_last(ring_.filled(), snapshot_);
  snapshot_rows_ = ring_.filled();
  job_ = r;
  busy_ = true;
  wake_.notify_all();
}

bool DiagnosisWorker::look(const Look& look) {
  std::lock_guard lock(mutex_);
  if (busy_ || pending_) return false;
  start_locked();
  snapshot_rows_ = std::min(look.rows, ring_.filled());
  ring_.copy_last(snapshot_rows_, snapshot_);
  look_job_ = look;
  busy_ = true;
  wake_.notify_all();
  return true;
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

bool DiagnosisWorker::idle() const {
  std::lock_guard lock(mutex_);
  return !busy_ && !pending_ && !result_ && !look_result_;
}

bool DiagnosisWorker::take_look(LookResult& out) {
  std::lock_guard lock(mutex_);
  if (!look_result_) return false;
  out = std::move(*look_result_);
  look_result_.reset();
  return true;
}

void DiagnosisWorker::run() {
  const auto m = static_cast<Eigen::Index>(plant_.n_inputs());
  const auto p = static_cast<Eigen::Index>(plant_.n_outputs());
  for (;;) {
    std::optional<Request> r;
    std::optional<Look> l;
    Eigen::MatrixXd u, residual;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [&] { return stop_ || job_.has_value() || look_job_.has_value(); });
      if (stop_) return;
      r.swap(job_);
      l.swap(look_job_);
      const auto n = static_cast<Eigen::Index>(snapshot_rows_);
      u = snapshot_.topLeftCorner(n, m);
      residual = snapshot_.block(0, m, n, p);
    }
    const auto started = std::chrono::steady_clock::now();
    const auto seconds = [&] {
      return std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    };
    if (l) {
      LookResult out;
      try {
        out = run_look(plant_, nominal_, u, residual, *l);
      } catch (const std::exception& e) {  // a bad window must not end the service
        out.look = *l;
        out.flagged.assign(plant_.n_outputs(), false);
        out.error = e.what();
        log::write(log::Level::kError, "diagnosis scan look at sample %lld failed: %s",
                   static_cast<long long>(l->seq), e.what());
      }
      std::lock_guard lock(mutex_);
      look_result_ = std::move(out);
      busy_ = false;
      continue;
    }
    msg::Diagnosis d;
    try {
      d = diagnose(plant_, nominal_, u, residual, *r);
    } catch (const std::exception& e) {  // a bad window must not end the service
      d.controller_id = r->controller_id;
      d.output = plant_.outputs[r->output];
      d.input = plant_.inputs[r->input];
      d.text = std::string("diagnosis failed: ") + e.what();
    }
    log::write(log::Level::kNotice, "controller '%s': diagnosis of %s -> %s over %d samples (%.2f s): %s",
               d.controller_id.c_str(), d.input.c_str(), d.output.c_str(), d.window, seconds(), d.text.c_str());
    std::lock_guard lock(mutex_);
    result_ = std::move(d);
    busy_ = false;
    completed_.fetch_add(1);
  }
}

DiagnosisWorker::LookResult DiagnosisWorker::run_look(const PlantModel& plant,
                                                      const std::vector<std::optional<DiscreteTf>>& nominal,
                                                      const Eigen::MatrixXd& u, const Eigen::MatrixXd& residual,
                                                      const Look& look) {
  LookResult out;
  out.look = look;
  const std::size_t p = plant.n_outputs();
  const diagnosis::Result result = diagnose_window(plant, nominal, u, residual, look.alpha);
  out.flagged = flagged_outputs(result, p);
  out.findings.resize(p);
  out.inputs.resize(p);
  out.lr.assign(p, 0.0);
  for (std::size_t j = 0; j < p; ++j) {
    const diagnosis::Finding* f = out.flagged[j] ? finding_for(result, j) : nullptr;
    if (f == nullptr) continue;
    describe_finding(plant, *f, out.findings[j]);
    out.inputs[j] = finding_input(*f, j);
    out.lr[j] = f->lr;
  }
  return out;
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
  // last value), with the raise as the monitor's verdict.
  std::vector<bool> flag(plant.n_outputs(), false);
  flag[r.output] = true;
  std::vector<std::vector<std::size_t>> located(plant.n_outputs());
  located[r.output].push_back(r.input);
  const diagnosis::Result result = diagnose_window(plant, nominal, u, residual, diagnosis::Settings{}.alpha, flag, located);
  const diagnosis::Finding* f = finding_for(result, r.output, r.input);
  if (f == nullptr) {
    d.text = "no physics hypothesis explains " + d.input + " -> " + d.output + " in the last " +
             std::to_string(d.window) + " samples" +
             (result.findings.empty() ? std::string() : " (findings elsewhere: " + result.findings.front().physics + ")");
    return d;
  }
  describe_finding(plant, *f, d);
  return d;
}

}  // namespace mpm
