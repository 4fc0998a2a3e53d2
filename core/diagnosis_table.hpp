// Internal to the diagnosis: the hypothesis table. Each row is one form of
// one physics word: where it applies (its scope and condition), how many
// parameters it has, how it is fitted, which test it must pass beyond the
// common fit and held-out tests, and the sentence that says what was found.
// The selection (diagnosis.cpp) only walks the table; a new physics word is
// an enumerator and its spelling (diagnosis_physics.*), one row here
// (diagnosis_table.cpp), its fit function and its sentence.
#pragma once

#include <cstddef>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "core/diagnosis_context.hpp"

namespace mpm::diagnosis {

// What one generator call of a row covers.
enum class Scope {
  channel,  // one channel (output j, input i)
  column,   // every modelled channel of input i
  row,      // every excited, modelled channel into output j
  plant,    // every output several inputs drive
  signal,   // recorded extra column `column` on output j (after the Granger screen)
  noise,    // output j's disturbance model, where no finding explains it (after the search)
};

// The test a candidate must pass beyond the fit-part likelihood ratio and
// the held-out confirmation (see passes() in diagnosis_score.cpp).
enum class Gate {
  beyond_noise,  // also explain the residual beyond an AR(3) change of the disturbance model
  held_out,      // nothing more (a recorded signal, a sensor lag, a changed disturbance model)
};

// What the parameter count is counted per.
enum class Per { finding, channel, output };

struct Site {
  std::size_t output = 0;  // channel, row, signal, noise
  std::size_t input = 0;   // channel, column
  std::size_t column = 0;  // signal: the extra column
};

// The numbers a sentence says that are not parameters of the fitted model
// (a standard error, the nominal time constant, ...).
using Facts = std::map<std::string, double>;

struct Hypothesis {
  Physics physics;
  Scope scope;
  int params;  // per `per`
  Per per;
  Gate gate;
  bool (*applies)(const Context&, const Site&);
  // Appends the best-fitting candidate(s) of this form (none when its own
  // pre-test fails); their parameters, `fitted` and facts set, not the summary.
  void (*fit)(const Context&, const Hypothesis&, const Site&, std::vector<Candidate>&);
  std::string (*sentence)(const Problem&, const Finding&, const Facts&);
  int count(std::size_t channels, std::size_t outputs) const {
    return params * static_cast<int>(per == Per::channel ? channels : per == Per::output ? outputs : 1);
  }
};

// Every row, in the order their candidates are generated (the order breaks
// ties in the selection, so it is part of the result).
std::span<const Hypothesis> hypothesis_table();

// Runs every row of `scope` that applies at `site`, in table order, and says
// each new candidate's sentence.
void run_scope(const Context& cx, Scope scope, const Site& site, std::vector<Candidate>& out);

// Fit functions (diagnosis_hypotheses.cpp: channel; diagnosis_patterns.cpp:
// column, row, plant, signal; diagnosis_noise.cpp: noise).
void fit_gain(const Context&, const Hypothesis&, const Site&, std::vector<Candidate>&);
void fit_dead_time(const Context&, const Hypothesis&, const Site&, std::vector<Candidate>&);
void fit_time_constant(const Context&, const Hypothesis&, const Site&, std::vector<Candidate>&);
void fit_extra_lag(const Context&, const Hypothesis&, const Site&, std::vector<Candidate>&);
void fit_integrator(const Context&, const Hypothesis&, const Site&, std::vector<Candidate>&);
void fit_missing_channel(const Context&, const Hypothesis&, const Site&, std::vector<Candidate>&);
void fit_actuator(const Context&, const Hypothesis&, const Site&, std::vector<Candidate>&);
void fit_column_gains(const Context&, const Hypothesis&, const Site&, std::vector<Candidate>&);
void fit_saturation(const Context&, const Hypothesis&, const Site&, std::vector<Candidate>&);
void fit_deadband(const Context&, const Hypothesis&, const Site&, std::vector<Candidate>&);
void fit_static_map(const Context&, const Hypothesis&, const Site&, std::vector<Candidate>&);
void fit_row_level_gain(const Context&, const Hypothesis&, const Site&, std::vector<Candidate>&);
void fit_sensor(const Context&, const Hypothesis&, const Site&, std::vector<Candidate>&);
void fit_plant_level_gain(const Context&, const Hypothesis&, const Site&, std::vector<Candidate>&);
void fit_signal_through_channel(const Context&, const Hypothesis&, const Site&, std::vector<Candidate>&);
void fit_signal_fopdt(const Context&, const Hypothesis&, const Site&, std::vector<Candidate>&);
void fit_disturbance_model(const Context&, const Hypothesis&, const Site&, std::vector<Candidate>&);

// Sentences (diagnosis_summary.cpp), from the finding and its facts only.
std::string say_gain(const Problem&, const Finding&, const Facts&);
std::string say_dead_time(const Problem&, const Finding&, const Facts&);
std::string say_time_constant(const Problem&, const Finding&, const Facts&);
std::string say_extra_lag(const Problem&, const Finding&, const Facts&);
std::string say_integrator(const Problem&, const Finding&, const Facts&);
std::string say_missing_channel(const Problem&, const Finding&, const Facts&);
std::string say_actuator(const Problem&, const Finding&, const Facts&);
std::string say_column_gains(const Problem&, const Finding&, const Facts&);
std::string say_saturation(const Problem&, const Finding&, const Facts&);
std::string say_deadband(const Problem&, const Finding&, const Facts&);
std::string say_static_map(const Problem&, const Finding&, const Facts&);
std::string say_level_gain(const Problem&, const Finding&, const Facts&);
std::string say_sensor(const Problem&, const Finding&, const Facts&);
std::string say_signal_through_channel(const Problem&, const Finding&, const Facts&);
std::string say_signal_fopdt(const Problem&, const Finding&, const Facts&);
std::string say_disturbance_model(const Problem&, const Finding&, const Facts&);
// The monitor's fallback (Physics::other): no hypothesis, no fit.
std::string say_other(const Problem&, const Finding&);

// Outputs with a modelled channel from input i; the excited, modelled
// channels into output j (with the model's prediction sum_i G_ji du_i).
std::vector<std::size_t> column_outputs(const Context& cx, std::size_t i);
struct RowPrediction {
  std::vector<Channel> channels;
  Vec total;
};
RowPrediction row_prediction(const Context& cx, std::size_t j);

// First order plus dead time from signal x to output j,
// K (1-a)/(1-a q^-1) q^-delay: the pole on a log grid (and 0), the delay in
// [min_delay, max_delay]; with refine_pole, the pole refined at the best delay.
struct Fopdt {
  double pole = 0.0;
  int delay = 0;
};
Fopdt best_fopdt(const Context& cx, std::size_t j, const Vec& x, int min_delay, int max_delay, bool refine_pole);

}  // namespace mpm::diagnosis
