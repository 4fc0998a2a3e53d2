// Internal to the diagnosis (core/diagnosis*.cpp): the prepared record, how
// a hypothesis's correction is scored, and the hypothesis generators.
#pragma once

#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "core/diagnosis.hpp"

namespace mpm::diagnosis {

struct Hypothesis;  // a row of the hypothesis table (diagnosis_table.hpp)

// The numbers a sentence says that are not parameters of the fitted model
// (a standard error, the nominal time constant, ...).
using Facts = std::map<std::string, double>;

// One output's current residual and its whitener.
// Recorded signals accepted as unmodeled inputs of this output stay free in
// every later fit: each hypothesis is fitted jointly with their regressors,
// and is scored against the signals-only fit, so a process-channel finding
// must improve the fit conditional on the accepted signals (in closed loop the
// controller moves the inputs to cancel them, so G_M u is correlated with
// them, and a correction fitted after a fixed subtraction would take up the
// error of the signals' coefficients).
struct OutputState {
  Vec d;               // residual with accepted corrections subtracted (missing: held)
  DiscreteTf whitener; // N^-1, or the AR part of an ARX fit
  Vec wd;              // whitener applied to d
  Vec base;            // residual with accepted process corrections subtracted, signals not
  Vec wbase;           // whitener applied to base
  std::vector<Vec> signals;   // regressors of the accepted recorded signals (raw)
  std::vector<Vec> wsignals;  // whitened
  Vec signal_theta;           // their coefficients in the signals-only fit: d = base - sum theta signal
  double fit_var = 1.0;   // whitened variance now, fit part
  double noise_change_var = 1.0;  // whitened variance, fit part, after an AR(3) change of the disturbance model alone
  double hold_var = 1.0;  // whitened variance now, held-out part
  double cv_var = 1.0;    // whitened variance now, cross-fitted over the folds (LinearFit::cv_var)
  Vec fold_var;           // its parts per fold (LinearFit::fold_var)
  Vec hold_error;         // whitened, mean-removed errors on the held-out part
};

struct Context {
  const Problem& problem;
  const Settings& settings;
  Segments seg;
  std::vector<char> valid;       // usable samples (finite, whitener settled)
  std::vector<OutputState> out;
  std::vector<Vec> gu;           // per channel (output major): G_ji du_i, empty without a channel
  Eigen::MatrixXd extra;         // extra columns, deviation from their fit mean, held
  std::vector<bool> excited;     // per input: moves on the fit part
  // The fewest samples any hypothesis may take an input to act: 1 when every
  // channel of the model is strictly proper (the recording's timing then
  // has u(k) act after y(k) is read, and a same-sample response in the data
  // can only be the controller's: u(k) is computed from y(k)), else 0.
  int min_input_delay = 0;
  // Whether make_candidate keeps a candidate's N-long columns (corrections,
  // regressors, held-out errors) once it is scored. The search over
  // candidates needs only their numbers, so diagnose() turns this off while
  // it generates them, then reruns the generator of the one it chooses with
  // `rebuilding` pointing at it, which keeps that one's columns only: what
  // the search holds is then a fixed number of columns, not a number that
  // grows with the candidates tried.
  bool keep_series = true;
  const struct Candidate* rebuilding = nullptr;
  std::size_t n_in() const { return problem.inputs.size(); }
  std::size_t n_out() const { return problem.outputs.size(); }
  const std::optional<DiscreteTf>& channel(std::size_t j, std::size_t i) const {
    return problem.nominal[j * n_in() + i];
  }
  // Samples before channel (j, i) responds: its delay plus num's leading zeros.
  int response_delay(std::size_t j, std::size_t i) const;
  bool has_channel(std::size_t j, std::size_t i) const {
    const auto& c = channel(j, i);
    return c && !c->is_zero();
  }
};

// The fit of one output under a hypothesis: correction c = c0 + sum theta x.
struct OutputFit {
  std::size_t output = 0;
  Vec correction;   // raw, full length: the change of d (with the signals' refitted coefficients)
  LinearFit fit;    // whitened; theta holds the hypothesis' own coefficients only
  Vec fixed;                    // the hypothesis' fixed correction c0 (may be empty)
  std::vector<Vec> regressors;  // the hypothesis' linear regressors X (raw)
  // The fit's whitened target and regressors, kept until the candidate is
  // scored: the test beyond a changed noise model refits on them.
  Vec whitened_target;                // empty: the output's own (wd, or wbase with signals)
  std::vector<Vec> whitened_regressors;
  Vec signal_theta;             // the accepted signals' coefficients in the joint fit
};

struct Candidate {
  const Hypothesis* hypothesis = nullptr;  // the table row that made it
  Finding finding;
  Facts facts;  // for the finding's sentence
  std::vector<OutputFit> fits;
  int params = 0;
  // Parameters searched on a grid that the record cannot identify without a
  // change (the ARMA(1,1) noise form's pole, which cancels its zero): the
  // evidence tests count them (test_params()), the selection score does not.
  int unidentified = 0;
  int test_params() const { return params + unidentified; }
  double lr = 0.0;        // sum over outputs of n_fit ln(before / after), whitened
  double z_hold = 0.0;    // projection test on the held-out part
  double z_expected = 0.0;  // what z_hold would be on average were the correction exactly right
  double hold_gain = 0.0; // sum over outputs of ln(before / after), held-out whitened variance
  double cv_gain = 0.0;   // the same for the cross-fitted variance (LinearFit::cv_var)
  // Of the folds judged (LinearFit::fold_var), how many the correction
  // improves out of sample (the sum over outputs of ln(before / after) > 0).
  int folds_judged = 0;
  int folds_improved = 0;
  // The held-out part's share of the samples judged (score() sets it; it
  // weights the pooled evidence, and 0 means there is none).
  double hold_share = 0.0;
  // The hypothesis fitted jointly with an AR(3) change of the disturbance
  // model, against that change alone: what it explains beyond a wrong N.
  double lr_beyond_noise = 0.0;
  // A transmitter lag where the plant file declares the variance of the
  // disturbances' white input: how much worse the fit part's log-likelihood
  // (LR scale) is with the one-step error variance tied to that declaration
  // through the lag's pole, (1 - a)^2 sigma^2, the pole refitted so, than
  // with the variance free (fit_sensor(); declared_variance_term() weighs it).
  std::optional<double> tied_variance_deviance;
  // A changed disturbance model (the noise row): the filter C that whitens
  // the output's residual further, the new model being N / C. Accepting the
  // candidate changes the output's whitener, not its residual.
  std::optional<DiscreteTf> whitener_change;
  // Where the candidate came from: the `rank`-th candidate of generator call
  // `group` (see rebuild_chosen), for a candidate whose columns were released.
  std::size_t group = 0;
  std::size_t rank = 0;
  double bic(double log_n) const;  // lr - params ln n
  double aic() const;              // lr - 2 params
};

// Drops a scored candidate's N-long columns; its numbers stay.
void release_series(Candidate& c);
// Whether make_candidate keeps c's columns (Context::keep_series, rebuilding).
bool keeps_series(const Context& cx, const Candidate& c);

// Fits output j with fixed correction c0 (may be empty) plus linear terms X,
// jointly with the output's accepted signal regressors. c0 and X are taken
// by value: they become the fit's `fixed` and `regressors`, moved, not
// copied, when the caller passes temporaries.
OutputFit fit_output(const Context& cx, std::size_t j, Vec c0, std::vector<Vec> X);
// -sum n ln(var): the objective to minimise over nonlinear parameters.
double objective(const Context& cx, const std::vector<OutputFit>& fits);
// The same for one output. A call objective(cx, {fit_output(...)}) takes this
// overload (a braced single fit is an exact match for the aggregate), so the
// fit's N-long columns are not copied into a vector for every point of a
// search.
double objective(const Context& cx, const OutputFit& fit);
// What objective(cx, {fit_output(cx, j, c0, X)}) gives, from the columns
// already whitened (wc0 = whitener c0, may be empty; wx = whitener X): for
// searches that form them in fewer filter passes (filters in series, or a
// lag of a whitened column, the whitener being linear and at rest at 0).
double whitened_objective(const Context& cx, std::size_t j, Vec wc0, const std::vector<const Vec*>& wx);
// The held-out projection test of a correction, from the whitened
// held-out errors before (e0) and after (e1) it, per output (score()).
struct HoldoutProjection {
  double z = 0.0;           // N(0, 1) when the correction is unrelated to e0
  double z_expected = 0.0;  // what z would be on average were the correction exactly right
};
HoldoutProjection project_holdout(const Context& cx, const std::vector<std::pair<const Vec*, const Vec*>>& errors);
// Fills lr, z_hold, hold_gain, cv_gain, the folds' counts and lr_beyond_noise.
void score(const Context& cx, Candidate& c);
// Regressors of a change of output j's disturbance model given residual r:
// r's first three lags (whitened, the lags of the whitened residual: AR(3)).
std::vector<Vec> noise_change_regressors(const Vec& r);
// A scored candidate of row h from its per-output fits: the parameter count
// is the row's (Hypothesis::count), or `params` where the fit chooses it.
Candidate make_candidate(const Context& cx, const Hypothesis& h, std::vector<Channel> channels,
                         std::vector<OutputFit> fits);
Candidate make_candidate(const Context& cx, const Hypothesis& h, std::vector<Channel> channels,
                         std::vector<OutputFit> fits, int params);
// The same for one output's fit, moved in (make_candidate(..., {std::move(f)})
// takes this overload: no copy of the fit's columns).
Candidate make_candidate(const Context& cx, const Hypothesis& h, std::vector<Channel> channels, OutputFit fit);
// Time constant in samples of a discrete pole in (0, 1); 0 otherwise.
double tau_of(double pole);

// Record preparation (diagnosis_prepare.cpp): the usable samples, the fit
// and held-out blocks, the excited inputs, G_ji du_i per channel, and each
// output's residual, whitener and scores as they stand.
Context prepare(const Problem& p, const Settings& s);
// Whitened variances and held-out errors of output j as it stands: its
// process-corrected residual less the signals-only fit of its accepted
// recorded signals.
void refresh(Context& cx, std::size_t j);

// Selection tests (diagnosis_score.cpp). The fit-part level of the family
// of `family` candidates; whether c passes the fit, held-out and its row's
// gate; its selection score (AIC on the fit part plus the held-out
// log-likelihood gain); the fit block of its finding (and the raw one).
double fit_level(const Settings& s, double family);
// The fit-part limit of a candidate with `params` parameters (with the
// held-out test), and the level its pooled evidence is held to.
double fit_limit(const Settings& s, double family, int params);
double pooled_level(const Settings& s, double family);
// The fit-part limit where the held-out part is uninformative (see passes()).
double uninformed_limit(const Settings& s, double family, int params);
bool passes(const Candidate& c, const Settings& s, double family);
// The out-of-sample part of passes(): the cross-fitted variance falls, over
// the record and on most of the folds judged.
bool improves_out_of_sample(const Candidate& c);
// Whether terms added to a fitted form (`df` more parameters) are there:
// their nested likelihood ratio on the fit part pooled with the held-out
// projection z of what they change, at `level`.
bool beyond_nested(double nested_lr, double z_hold, int df, double level);
// The p-value of c's fit and held-out evidence pooled: the fit part's
// sqrt(lr) and the held-out z, each weighted by the square root of its
// share of the samples. Were the correction exactly right, sqrt(lr) would
// be about sqrt((1 - h) n d) and z about sqrt(h n d) for an effect of d per
// sample, so the weighted sum grows as sqrt(n d): all of the record's
// evidence in one direction. (lr + z^2 spent a degree of freedom on z's
// size whatever its share, and counted z < 0 as no evidence rather than as
// evidence against.)
double pooled_evidence_p(const Candidate& c);
// P(sqrt(1 - h) sqrt(X) + sqrt(h) Z >= t) for X ~ chi-square(params) and Z ~
// N(0, 1) independent, h = hold_share in (0, 1): the null tail of the pooled
// evidence of passes(), the fit part's sqrt(lr) and the held-out z weighted
// by their shares of the samples.
double pooled_evidence_survival(double t, int params, double hold_share);
double selection_score(const Context& cx, const Candidate& c);
// The variance of output j's disturbances' white input as the plant file
// declares it (with a noise model and a positive value), else nothing.
inline std::optional<double> declared_noise_variance(const Problem& p, std::size_t j) {
  if (j >= p.noise.size() || !p.noise[j] || j >= p.noise_variance.size() || !p.noise_variance[j] ||
      !(*p.noise_variance[j] > 0.0))
    return std::nullopt;
  return p.noise_variance[j];
}
FitNumbers fit_numbers(const Context& cx, const Candidate& c, FitNumbers& raw);


// Pole grid for lags: time constants log-spaced in [tau_lo, tau_hi] samples.
std::vector<double> lag_pole_grid(double tau_lo, double tau_hi, int points);

std::string fmt(double v, int digits = 3);

}  // namespace mpm::diagnosis
