// OVERVIEW
// The physics behind a live alarm: mpmd keeps the most recent samples in a
// ring buffer (inputs and the residual the monitor saw, allocated at setup)
// and, when an output is raised, runs the offline diagnosis of
// core/diagnosis.hpp (what `mpm diagnose` runs) over them on one background
// thread. The per-sample path only writes one row of the ring; the diagnosis
// (a fraction of a second to a few seconds) never delays a sample.
//
// One request at a time: a raise while the worker is busy is kept as the one
// pending request (a later one replaces it, counted as coalesced) and handed
// over when the worker is free; nothing queues without bound. Results are
// collected on the main thread (take), which publishes them: the worker never
// touches the transport or the monitor.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include <Eigen/Dense>

#include "core/plant_model.hpp"
#include "core/transfer_function.hpp"
#include "transport/messages.hpp"

namespace mpm {

class DiagnosisWorker {
 public:
  struct Request {
    std::size_t output = 0;
    std::size_t input = 0;
    std::int64_t utime = 0;
    std::int64_t seq = 0;
    std::string controller_id;
  };

  // Allocates the ring (window samples). The thread starts at the first request.
  DiagnosisWorker(const PlantModel& plant, std::size_t window);
  ~DiagnosisWorker();
  DiagnosisWorker(const DiagnosisWorker&) = delete;
  DiagnosisWorker& operator=(const DiagnosisWorker&) = delete;

  // Real-time safe: one sample's absolute inputs and residual (NaN = missing
  // or not used by the monitor).
  void record(const double* u, const double* residual) noexcept;

  // At a raise (main thread): hands the window to the worker, or keeps the
  // request pending when it is busy. Returns false when it replaced an
  // earlier pending request (coalesced).
  bool request(Request r);

  // Main thread: a finished diagnosis (true), after handing over a pending
  // request if the worker has become free.
  bool take(msg::Diagnosis& out);

  std::uint64_t coalesced() const noexcept { return coalesced_; }
  std::uint64_t completed() const noexcept { return completed_.load(); }
  std::size_t window() const noexcept { return window_; }

  // The diagnosis of `u` (samples x inputs, absolute) and `residual`
  // (samples x outputs) for a raise of (output, input): what the worker runs,
  // exposed for tests.
  static msg::Diagnosis diagnose(const PlantModel& plant, const std::vector<std::optional<DiscreteTf>>& nominal,
                                 const Eigen::MatrixXd& u, const Eigen::MatrixXd& residual, const Request& r);

 private:
  void submit_locked(const Request& r);  // copies the ring; mutex_ held
  void run();

  PlantModel plant_;
  std::vector<std::optional<DiscreteTf>> nominal_;
  std::size_t window_;
  Eigen::MatrixXd ring_;  // window x (inputs + outputs), row `head_` is next
  std::size_t head_ = 0;
  std::size_t filled_ = 0;

  std::mutex mutex_;
  std::condition_variable wake_;
  std::thread thread_;
  bool stop_ = false;
  bool busy_ = false;               // a job handed over and not yet finished
  std::optional<Request> job_;      // handed over, not yet started
  std::optional<Request> pending_;  // waiting for the worker to be free
  Eigen::MatrixXd snapshot_;        // the window handed over, oldest first
  std::size_t snapshot_rows_ = 0;
  std::optional<msg::Diagnosis> result_;
  std::uint64_t coalesced_ = 0;
  std::atomic<std::uint64_t> completed_{0};
};

}  // namespace mpm
