// OVERVIEW
// Offline diagnosis of model-plant mismatch: names the physics behind a
// mismatch by comparing structured hypotheses, each a change of the nominal
// model with one to three physical parameters (gain, dead time, time
// constant, extra lag, integrator, missing channel, actuator / sensor lag,
// saturation, backlash, operating-point gain, an unmodelled recorded signal,
// a changed disturbance model).
//
// Every hypothesis predicts a correction c = (G_P - G_M) u of the residual
// d~ = y - G_M u. It is scored by prediction-error minimisation of the
// whitened residual W (d~ - c), W = N^-1 when the plant file gives N, else an
// AR model of the residual estimated with the inputs in the regression (so
// that the mismatch does not leak into it). Whitening is what keeps the fit
// consistent in closed loop (direct prediction-error method).
// Parameters are fitted on seven of ten interleaved blocks; each candidate must
// pass a likelihood-ratio test there (chi-square, Bonferroni over all the
// candidates tried) and improve the prediction on the held-out part
// (the other three blocks), which it never saw. Candidates are chosen
// greedily: the best by AIC on the fit part plus the held-out log-likelihood
// gain is accepted, its correction is subtracted, and the rest are refitted. Recorded
// signals accepted as unmodeled inputs of an output stay free regressors of
// that output: every later hypothesis there is fitted jointly with them and
// tested against the signals-only fit, so it must earn its place conditional
// on them (the controller moves the inputs to cancel them, so G_M u is
// correlated with them).
//
// The hypotheses are the rows of one table (diagnosis_table.hpp): physics
// word, scope, parameter count, where it applies, its fit, its gate and its
// sentence. The code is split the same way: record preparation
// (diagnosis_prepare.cpp), scoring (diagnosis_score.cpp), selection
// (diagnosis.cpp), the fits (diagnosis_hypotheses.cpp: channel;
// diagnosis_patterns.cpp: column, row, plant, signal; diagnosis_noise.cpp)
// and the sentences (diagnosis_summary.cpp).
//
// Memory and time. What is held is a fixed number of N-long columns (N
// samples), never a number that grows with the candidates tried: the
// problem's own (du and u_abs per input, the residual per output, each extra
// column), the prepared context's (per output: residual, its whitened copy,
// the process-corrected base and its whitened copy, the held-out errors, two
// per accepted recorded signal; G_ji du_i per channel; the extra columns),
// and per generator thread the temporaries of the one fit in progress (its
// correction, regressors and their whitened copies: about 25 columns at the
// largest). Candidates keep only their numbers during the search
// (Context::keep_series); the chosen one is rebuilt with its columns by
// rerunning its generator, which is deterministic. No column is decimated or
// capped. Whole-record filtering is DiscreteFilter's arithmetic without its
// per-sample history shifts (diagnosis_signal.hpp); least squares sum over
// runs of the fit part in blocks; the generators of one round run on
// Settings::threads threads, their candidates taken in call order, so the
// result does not depend on the thread count.
#pragma once

#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "core/diagnosis_physics.hpp"
#include "core/diagnosis_signal.hpp"
#include "core/field_table.hpp"
#include "core/transfer_function.hpp"

namespace mpm::diagnosis {

struct Settings {
  // Family-wise false-alarm level of each of the diagnosis' looks: the
  // process rounds, and the changed disturbance model where no finding
  // explains an output. With the monitor's verdict beside them, `mpm
  // diagnose` bounds a healthy record's chance of a finding by
  // healthy_finding_bound(alpha) (daemon/offline.hpp; docs/method.md
  // measures it).
  double alpha = 1e-3;
  double holdout_level = 0.05;  // level of the held-out confirmation (holdout_z is its quantile)
  double holdout_z = 1.645;     // one-sided 5 % paired test on the held-out part
  // Below this expected z (what an exact correction would give on the
  // held-out part) the held-out test is uninformative and the fit-part test
  // decides alone (passes() in diagnosis_score.cpp).
  double holdout_informative_z = 1.0;
  // Level of the test that a process candidate explains the residual beyond
  // a changed disturbance model (the gate of score()): it chooses between two
  // explanations of a mismatch the family-wise test has already found, so it
  // is not divided over the family.
  double beyond_noise_level = 0.01;
  int ar_order = 10;            // AR whitener order when N is unknown
  int input_lags = 10;          // input lags in the ARX noise estimate / Granger tests
  int max_findings = 8;
  // The fewest usable samples on the fit and the held-out part for the
  // hypotheses to be fitted at all; below them the report is the monitor's.
  // Short records hold the level worse (docs/method.md, "Short records":
  // healthy records of 400 samples got a finding 13 times in 900 with
  // limits of 120 and 50), so the limits stay where they are.
  long min_fit_samples = 200;
  long min_hold_samples = 100;
  // Below this many fit samples (records of about 1000 samples) the report
  // notes that its false-alarm bound was not seen to hold: healthy records
  // of 500-800 samples got a finding about 2.5 times as often as the bound
  // (docs/method.md, "Short records").
  long level_held_fit_samples = 600;
  // Which third of the ten interleaved blocks is held out: 2 (the third,
  // sixth and ninth tenths of the record, where every method choice was
  // judged), 0 or 1 (the blocks moved by one or two). Another phase is the
  // same method on another split: how much a result moves with it is the
  // split's luck (docs/method.md, "The split's luck").
  int holdout_phase = 2;
  int max_extra_delay = 15;     // dead-time search range (samples)
  bool verbose = false;         // report every candidate through the progress callback
  std::size_t threads = 1;      // hypothesis generators run on this many threads (same result for any)

  // The settings an engineer sets (`mpm diagnose --alpha`, and
  // `--holdout-phase` to see whether a finding stands on another split); the
  // others are the method's.
  static const std::vector<FieldRow<Settings>>& fields();
};

struct Problem {
  std::vector<std::string> inputs;
  std::vector<std::string> outputs;
  Eigen::MatrixXd du;        // samples x inputs: u - u0, missing samples held
  Eigen::MatrixXd u_abs;     // absolute inputs (reports)
  Eigen::MatrixXd residual;  // samples x outputs, NaN = missing
  std::vector<std::string> extra_names;
  Eigen::MatrixXd extra;     // samples x extra columns (absolute; NaN = missing)
  std::vector<std::optional<DiscreteTf>> nominal;  // output major; nullopt / zero = no channel
  std::vector<std::optional<DiscreteTf>> noise;    // per output, N when known
  std::vector<std::optional<double>> noise_variance;  // per output, the variance of N's white input a, when known
  std::size_t begin = 0;           // first sample analysed (after the start-up transient)
  std::vector<bool> monitor_flag;  // per output: the monitor's verdict (mismatch)
  std::vector<std::vector<std::size_t>> monitor_located;  // per output: inputs located
  double sample_time = 1.0;
};

struct Channel {
  std::size_t output = 0;
  std::optional<std::size_t> input;  // nullopt: no input (signal / disturbance)
};

struct FitNumbers {
  double residual_variance_before = 0.0;
  double residual_variance_after = 0.0;
  double holdout_variance_before = 0.0;
  double holdout_variance_after = 0.0;
};

struct Finding {
  std::vector<Channel> channels;
  std::string physics;  // word(Physics): set only from the hypothesis table's word
  std::optional<std::string> signal;
  std::string summary;
  std::optional<DiscreteTf> nominal;
  std::optional<DiscreteTf> fitted;
  std::map<std::string, double> parameters;  // extra fields of `fitted`
  FitNumbers fit;   // one-step prediction-error variances (whitened residual), summed over outputs
  FitNumbers raw;   // the raw residual's variances, for the record
  double lr = 0.0;  // likelihood-ratio statistic on the fit part
  int params = 0;
  // Other words on the same channels that the data cannot tell from
  // `physics` (they pass every test and their selection score is within
  // max(3.84, 3 % of this one's): alternatives() in diagnosis.cpp), best
  // first. The word reported is the best.
  std::vector<std::string> alternatives;
  // Why a fitted parameter is physically impossible or has the wrong sign
  // (a gain that reverses the channel: a heater that cools); empty when
  // plausible. The rules are implausibility() in diagnosis_table.cpp.
  std::string implausible;
};

struct Result {
  bool mismatch = false;
  std::vector<Finding> findings;
  std::vector<std::string> notes;  // why parts were not analysed
};

// Progress callback for long steps (may be empty).
using Progress = void (*)(const char* message);

Result diagnose(const Problem& problem, const Settings& settings = {}, Progress progress = nullptr);

}  // namespace mpm::diagnosis
