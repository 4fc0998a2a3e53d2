// OVERVIEW
// The physics behind a live alarm: mpmd keeps the most recent samples in a
// ring buffer (inputs and the residual the monitor saw, allocated at setup)
// and, when an output is raised, runs the offline diagnosis of
// core/diagnosis.hpp (what `mpm diagnose` runs) over them on one background
// thread. The per-sample path only writes one row of the ring; the diagnosis
// (a fraction of a second to a few seconds) never delays a sample.
//
// The same thread runs the looks of the periodic diagnosis scan
// (core/diagnosis_scan.hpp) over the last rows of the ring: at a checkpoint
// the per-sample path only copies those rows into the worker, or, when it is
// still busy, skips the look (the caller counts it); nothing waits.
//
// One request at a time: a raise while the worker is busy is kept as the one
// pending request (a later one replaces it, counted as coalesced) and handed
// over when the worker is free; nothing queues without bound. Results are
// collected on the main thread (take, take_look), which publishes them: the
// worker never touches the transport or the monitor.
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

#include "core/diagnosis_scan.hpp"
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

  // A look of the diagnosis scan: the last `rows` samples at level alpha.
  struct Look {
    std::size_t rows = 0;
    double alpha = 0.0;
    std::int64_t utime = 0;
    std::int64_t seq = 0;
  };
  // Its outcome: per output, whether an accepted finding names it, and that
  // finding (the best on the output) as a diagnosis message; its channel's
  // input and likelihood ratio.
  struct LookResult {
    Look look;
    std::vector<bool> flagged;
    std::vector<msg::Diagnosis> findings;
    std::vector<std::optional<std::size_t>> inputs;
    std::vector<double> lr;
    std::string error;  // the diagnosis failed (no output flagged)
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

  // At a scan checkpoint (main thread): hands the last look.rows samples to
  // the worker; false (nothing done) when it is busy or a request waits.
  bool look(const Look& look);
  // Main thread: a finished look (true).
  bool take_look(LookResult& out);

  // Nothing handed over, pending or waiting to be taken (tests wait for it).
  bool idle() const;

  std::uint64_t coalesced() const noexcept { return coalesced_; }
  std::uint64_t completed() const noexcept { return completed_.load(); }
  std::size_t window() const noexcept { return window_; }

  // The diagnosis of `u` (samples x inputs, absolute) and `residual`
  // (samples x outputs) for a raise of (output, input): what the worker runs,
  // exposed for tests.
  static msg::Diagnosis diagnose(const PlantModel& plant, const std::vector<std::optional<DiscreteTf>>& nominal,
                                 const Eigen::MatrixXd& u, const Eigen::MatrixXd& residual, const Request& r);
  // A scan look over `u` and `residual` (what the worker runs for look()).
  static LookResult run_look(const PlantModel& plant, const std::vector<std::optional<DiscreteTf>>& nominal,
                             const Eigen::MatrixXd& u, const Eigen::MatrixXd& residual, const Look& look);

 private:
  void submit_locked(const Request& r);  // copies the ring; mutex_ held
  void start_locked();                   // the thread, at the first job; mutex_ held
  void run();

  PlantModel plant_;
  std::vector<std::optional<DiscreteTf>> nominal_;
  std::size_t window_;
  SampleRing ring_;  // window x (inputs, then residuals)

  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::thread thread_;
  bool stop_ = false;
  bool busy_ = false;               // a job handed over and not yet finished
  std::optional<Request> job_;      // handed over, not yet started
  std::optional<Look> look_job_;    // a scan look handed over, not yet started
  std::optional<Request> pending_;  // waiting for the worker to be free
  Eigen::MatrixXd snapshot_;        // the window handed over, oldest first
  std::size_t snapshot_rows_ = 0;
  std::optional<msg::Diagnosis> result_;
  std::optional<LookResult> look_result_;
  std::uint64_t coalesced_ = 0;
  std::atomic<std::uint64_t> completed_{0};
};

}  // namespace mpm
