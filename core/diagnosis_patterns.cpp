// Hypotheses that span several channels (one input's column: actuator lag,
// saturation, backlash, operating-point gain; one output's row: sensor lag)
// and recorded signals the model leaves out (unmodeled_input). Their rows are
// in diagnosis_table.cpp, their sentences in diagnosis_summary.cpp.
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/chi_square.hpp"
#include "core/diagnosis_table.hpp"

namespace mpm::diagnosis {

std::vector<std::size_t> column_outputs(const Context& cx, std::size_t i) {
  std::vector<std::size_t> js;
  for (std::size_t j = 0; j < cx.n_out(); ++j)
    if (cx.has_channel(j, i)) js.push_back(j);
  return js;
}

// The model's prediction of output j, sum_i G_ji du_i over the excited
// inputs with a channel, and those channels.
RowPrediction row_prediction(const Context& cx, std::size_t j) {
  RowPrediction r{{}, Vec::Zero(cx.problem.du.rows())};
  for (std::size_t i = 0; i < cx.n_in(); ++i)
    if (cx.has_channel(j, i) && cx.excited[i]) {
      r.channels.push_back({j, i});
      r.total += cx.gu[j * cx.n_in() + i];
    }
  return r;
}

namespace {

std::vector<Channel> column_channels(const std::vector<std::size_t>& js, std::size_t i) {
  std::vector<Channel> cs;
  for (std::size_t j : js) cs.push_back({j, i});
  return cs;
}

// Corrections G_ji (v - du_i) for every output of the column.
std::vector<OutputFit> input_change_fits(const Context& cx, std::size_t i, const std::vector<std::size_t>& js,
                                         const Vec& v) {
  const Vec delta = v - cx.problem.du.col(static_cast<Index>(i));
  std::vector<OutputFit> fits;
  for (std::size_t j : js) fits.push_back(fit_output(cx, j, simulate(*cx.channel(j, i), delta), {}));
  return fits;
}

// The objective of those corrections, as the searches need it: one filter
// pass per output (the channel and the output's whitener in series) and no
// raw columns. The same number as objective(cx, input_change_fits(...)) up
// to rounding.
double input_change_objective(const Context& cx, std::size_t i, const std::vector<std::size_t>& js, const Vec& v) {
  const Vec delta = v - cx.problem.du.col(static_cast<Index>(i));
  double sum = 0.0;
  for (std::size_t j : js) {
    Vec wc0 = simulate(series(cx.out[j].whitener, *cx.channel(j, i)), delta);
    sum += whitened_objective(cx, j, std::move(wc0), {});
  }
  return sum;
}

}  // namespace

// Gains changed on every channel of one input, each by its own factor (a
// valve whose split drifted, a feed whose composition changed): one finding,
// one factor per channel, so that a channel too weak to pass alone is named
// with the strong one it moves with. The selection takes it only where the
// gain is, on each of its channels, as good an explanation as any other
// form (column_gains_consistent in diagnosis.cpp).
void fit_column_gains(const Context& cx, const Hypothesis& h, const Site& s, std::vector<Candidate>& out) {
  const std::size_t i = s.input;
  // The outputs' fits are independent, so the subset of channels with the
  // best BIC is those whose own gain pays its parameter (LR above ln n): a
  // channel that did not change is left out, not carried along by the others.
  const double log_n = std::log(static_cast<double>(cx.seg.fit_samples()));
  std::vector<std::size_t> js;
  std::vector<OutputFit> fits;
  for (std::size_t j : column_outputs(cx, i)) {
    OutputFit f = fit_output(cx, j, Vec(), {cx.gu[j * cx.n_in() + i]});
    if (-objective(cx, f) <= log_n) continue;
    js.push_back(j);
    fits.push_back(std::move(f));
  }
  if (js.size() < 2) return;
  std::vector<double> factors, ses;
  for (const OutputFit& f : fits) {
    factors.push_back(1.0 + f.fit.theta(0));
    ses.push_back(f.fit.theta_se(0));
  }
  Candidate c = make_candidate(cx, h, column_channels(js, i), std::move(fits));
  c.finding.nominal = *cx.channel(js[0], i);
  DiscreteTf fitted = *cx.channel(js[0], i);
  for (double& b : fitted.num) b *= factors[0];
  c.finding.fitted = fitted;
  for (std::size_t r = 0; r < js.size(); ++r) {
    const std::string suffix = "_" + cx.problem.outputs[js[r]];
    c.finding.parameters["gain_factor" + suffix] = factors[r];
    c.facts["gain_factor_se" + suffix] = ses[r];
  }
  out.push_back(std::move(c));
}

void fit_actuator(const Context& cx, const Hypothesis& h, const Site& s, std::vector<Candidate>& out) {
  const std::size_t i = s.input;
  const auto js = column_outputs(cx, i);
  const Vec u = cx.problem.du.col(static_cast<Index>(i));
  const auto lagged = [&](double a) { return simulate(unit_lag(a), u); };
  const double a = minimise_on_grid(lag_pole_grid(0.3, 30.0, 16),
                                    [&](double v) { return input_change_objective(cx, i, js, lagged(v)); });
  Candidate c = make_candidate(cx, h, column_channels(js, i), input_change_fits(cx, i, js, lagged(a)));
  c.finding.nominal = *cx.channel(js[0], i);
  c.finding.fitted = series(*cx.channel(js[0], i), unit_lag(a));
  c.finding.parameters["actuator_lag_pole"] = a;
  c.finding.parameters["actuator_time_constant"] = tau_of(a) * cx.problem.sample_time;
  out.push_back(std::move(c));
}

void fit_saturation(const Context& cx, const Hypothesis& h, const Site& s, std::vector<Candidate>& out) {
  const std::size_t i = s.input;
  const auto js = column_outputs(cx, i);
  const Vec u = cx.problem.du.col(static_cast<Index>(i));
  std::vector<double> sorted;
  for (Index k = 0; k < u.size(); ++k)
    if (cx.seg.fit[static_cast<std::size_t>(k)]) sorted.push_back(u(k));
  std::sort(sorted.begin(), sorted.end());
  auto quantile = [&](double q) { return sorted[static_cast<std::size_t>(q * static_cast<double>(sorted.size() - 1))]; };
  double best_obj = std::numeric_limits<double>::infinity(), best_limit = 0.0;
  bool upper = true;
  // Each side's limit anywhere in the recorded range, not only beyond the
  // median: in closed loop the controller, which knows no stop, winds the
  // input far past it, so an actuator that cannot go below its working
  // point is recorded below it most of the time (a stop drawn at the 2 %
  // quantile of the matched run was reached by 97 % of the samples, and
  // with the search on the lower half only it came out a static map).
  std::vector<double> grid;
  for (int k = 0; k <= 24; ++k) grid.push_back(0.01 + 0.98 * k / 24.0);
  for (int side = 0; side < 2; ++side) {
    auto f = [&](double q) {
      const double lim = quantile(std::clamp(q, 0.0, 1.0));
      const Vec v = side == 0 ? clipped(u, -1e300, lim) : clipped(u, lim, 1e300);
      return input_change_objective(cx, i, js, v);
    };
    const double q = minimise_on_grid(grid, f);
    const double o = f(q);
    if (o < best_obj) {
      best_obj = o;
      best_limit = quantile(std::clamp(q, 0.0, 1.0));
      upper = side == 0;
    }
  }
  const Vec v = upper ? clipped(u, -1e300, best_limit) : clipped(u, best_limit, 1e300);
  Candidate c = make_candidate(cx, h, column_channels(js, i), input_change_fits(cx, i, js, v));
  const double u0 = cx.problem.u_abs(0, static_cast<Index>(i)) - cx.problem.du(0, static_cast<Index>(i));
  c.finding.nominal = *cx.channel(js[0], i);
  c.finding.fitted = *cx.channel(js[0], i);
  c.finding.parameters[upper ? "upper_limit" : "lower_limit"] = u0 + best_limit;
  out.push_back(std::move(c));
}

void fit_deadband(const Context& cx, const Hypothesis& h, const Site& s, std::vector<Candidate>& out) {
  const std::size_t i = s.input;
  const auto js = column_outputs(cx, i);
  const Vec u = cx.problem.du.col(static_cast<Index>(i));
  const Vec moves = (u.tail(u.size() - 1) - u.head(u.size() - 1)).cwiseAbs();
  const double scale = std::max(1e-12, moves.mean());
  std::vector<double> grid;
  for (int k = 0; k <= 14; ++k) grid.push_back(std::log(0.05 * scale) + k * std::log(200.0) / 14.0);
  const auto played = [&](double lw) { return backlash(u, std::exp(lw)); };
  const double lw =
      minimise_on_grid(grid, [&](double v) { return input_change_objective(cx, i, js, played(v)); });
  Candidate c = make_candidate(cx, h, column_channels(js, i), input_change_fits(cx, i, js, played(lw)));
  c.finding.nominal = *cx.channel(js[0], i);
  c.finding.fitted = *cx.channel(js[0], i);
  c.finding.parameters["backlash_width"] = std::exp(lw);
  out.push_back(std::move(c));
}

namespace {

// Mean of x over the fit part.
double fit_mean(const Context& cx, const Vec& x) {
  double sum = 0.0;
  Index n = 0;
  for (Index k = 0; k < x.size(); ++k)
    if (cx.seg.fit[static_cast<std::size_t>(k)]) {
      sum += x(k);
      ++n;
    }
  return n ? sum / static_cast<double>(n) : 0.0;
}

// A static nonlinearity of input i around its working level, on the
// channels js (one channel, or the input's whole column): the effective
// input is du + a_j du + b_j e(v) + c_j o(v), with v = u - mean(u) on the fit
// part, e(v) = v^2 and o(v) = v |v|, each centred and the odd term made
// orthogonal to v on the fit part. Without the linear term, an input whose
// mean sits away from the model's operating point makes v^2 a plain gain
// change in disguise (two gains on one column then lost to one "nonlinear
// gain"); without the odd term a map such as v (1 + a |v|) looked exactly a
// gain. So a candidate is only offered when its nonlinear terms are
// significant beyond the best linear gains on the same channels (nested
// likelihood ratio, one degree of freedom per term and channel): a plain
// gain change is left to the gain hypotheses.
void static_map(const Context& cx, const Hypothesis& h, std::size_t i, const std::vector<std::size_t>& js,
                std::vector<Candidate>& out) {
  const Vec u = cx.problem.du.col(static_cast<Index>(i));
  const Vec v = (u.array() - fit_mean(cx, u)).matrix();
  Vec even = v.cwiseProduct(v);
  even.array() -= fit_mean(cx, even);
  // The odd term bends at the input's mean working level: where the plant
  // file gives no operating point, du = 0 is the record's first sample,
  // which the shared cases start away from the point their maps bend at
  // (u1 at 16.7 against 15); v^2 needs no centre (about any level it is v^2
  // plus linear and constant terms).
  Vec odd = v.cwiseProduct(v.cwiseAbs());
  double vv = 0.0, ov = 0.0;
  for (Index k = 0; k < v.size(); ++k)
    if (cx.seg.fit[static_cast<std::size_t>(k)]) {
      vv += v(k) * v(k);
      ov += odd(k) * v(k);
    }
  if (vv <= 0.0) return;
  odd -= (ov / vv) * v;
  odd.array() -= fit_mean(cx, odd);
  // The full map (linear, even and odd terms), and each nonlinear term
  // alone beside the linear one: an even map (v - c v^2) or an odd one
  // (v / (1 + a |v|)) costs one parameter per channel less, which a weak
  // bend needs to beat the plain gain on the selection score.
  struct Form {
    bool even, odd;
  };
  // Per channel, once for the three forms: the terms through the channel and
  // the best linear gain's fit (its variance and held-out errors), which
  // each form is nested against.
  std::vector<Vec> even_response, odd_response;
  std::vector<LinearFit> linear;
  for (std::size_t j : js) {
    const DiscreteTf& g = *cx.channel(j, i);
    even_response.push_back(simulate(g, even));
    odd_response.push_back(simulate(g, odd));
    linear.push_back(fit_output(cx, j, Vec(), {cx.gu[j * cx.n_in() + i]}).fit);
  }
  for (const Form form : {Form{true, true}, Form{false, true}, Form{true, false}}) {
    const int terms = static_cast<int>(form.even) + static_cast<int>(form.odd);
    std::vector<OutputFit> fits;
    double nested = 0.0;
    for (std::size_t r = 0; r < js.size(); ++r) {
      const std::size_t j = js[r];
      std::vector<Vec> regs{cx.gu[j * cx.n_in() + i]};
      if (form.even) regs.push_back(even_response[r]);
      if (form.odd) regs.push_back(odd_response[r]);
      fits.push_back(fit_output(cx, j, Vec(), regs));
      nested += std::log(linear[r].fit_var / fits.back().fit.fit_var);
    }
    nested *= static_cast<double>(cx.seg.fit_samples());
    std::vector<std::pair<const Vec*, const Vec*>> bend_errors;
    for (std::size_t r = 0; r < js.size(); ++r) bend_errors.push_back({&linear[r].hold_error, &fits[r].fit.hold_error});
    const double z_bend = project_holdout(cx, bend_errors).z;
    const auto n_ch = static_cast<int>(js.size());
    // Whether the bend is there beyond the best linear gains is a choice
    // between two explanations of a mismatch the candidate's own family-wise
    // test decides: at Settings::beyond_noise_level, as the other such
    // choice, not divided over the family (at the family's level a soft
    // saturation of a quarter of the gain over the input's range was named
    // a gain on 46 of 120 randomised runs, 33 at this level), with the
    // held-out part's word on the bend pooled in (beyond_nested()): the
    // projection of what the map changes in the linear gain's correction
    // onto the errors that gain leaves on the held-out blocks.
    if (!beyond_nested(nested, z_bend, terms * n_ch, cx.settings.beyond_noise_level)) continue;
    std::vector<Channel> cs = column_channels(js, i);
    Candidate c = make_candidate(cx, h, cs, fits, (1 + terms) * n_ch);
    c.finding.nominal = *cx.channel(js[0], i);
    c.finding.fitted = *cx.channel(js[0], i);
    c.finding.parameters["nonlinear_lr"] = nested;
    c.finding.parameters["nonlinear_holdout_z"] = z_bend;
    for (std::size_t r = 0; r < js.size(); ++r) {
      const LinearFit& f = c.fits[r].fit;
      const std::string suffix = js.size() == 1 ? std::string() : "_" + cx.problem.outputs[js[r]];
      c.finding.parameters["gain_factor" + suffix] = 1.0 + f.theta(0);
      c.finding.parameters["even_coefficient" + suffix] = form.even ? f.theta(1) : 0.0;
      c.finding.parameters["odd_coefficient" + suffix] = form.odd ? f.theta(form.even ? 2 : 1) : 0.0;
    }
    c.facts["working_level"] = cx.problem.u_abs(0, static_cast<Index>(i)) - u(0) + fit_mean(cx, u);
    out.push_back(std::move(c));
  }
}

// Gain varying with the output's own level: y = G u (1 + b G u), the
// correction b (G_M u)^2 over the whole row, one slope b per output. A
// process linearised at one operating point and run away from it has this
// form (a tank: every gain into it scales with the square root of its
// level): the level sets the gain of every input into that output at once,
// which per-input u^2 terms cannot say when the inputs move together in
// closed loop. Over several outputs it is one candidate, so that it is
// weighed as one explanation against the per-input ones.
void level_gain(const Context& cx, const Hypothesis& h, const std::vector<std::size_t>& js,
                std::vector<Candidate>& out) {
  std::vector<OutputFit> fits;
  std::vector<Channel> cs;
  for (std::size_t j : js) {
    const RowPrediction row = row_prediction(cx, j);
    fits.push_back(fit_output(cx, j, Vec(), {row.total.cwiseProduct(row.total)}));
    cs.insert(cs.end(), row.channels.begin(), row.channels.end());
  }
  const auto first = static_cast<std::size_t>(cs[0].input.value());
  Candidate c = make_candidate(cx, h, cs, fits);
  c.finding.nominal = *cx.channel(js[0], first);
  c.finding.fitted = *cx.channel(js[0], first);
  for (std::size_t r = 0; r < js.size(); ++r)
    c.finding.parameters["gain_slope_per_unit_" + cx.problem.outputs[js[r]]] = fits[r].fit.theta(0);
  out.push_back(std::move(c));
}

}  // namespace

void fit_static_map(const Context& cx, const Hypothesis& h, const Site& s, std::vector<Candidate>& out) {
  const auto js = column_outputs(cx, s.input);
  static_map(cx, h, s.input, js, out);
  if (js.size() >= 2)
    for (std::size_t j : js) static_map(cx, h, s.input, {j}, out);
}

void fit_row_level_gain(const Context& cx, const Hypothesis& h, const Site& s, std::vector<Candidate>& out) {
  level_gain(cx, h, {s.output}, out);
}

// A transmitter lag of pole a leaves the disturbances' white input of
// declared variance sigma^2 a one-step prediction error of variance
// p(a) = (1 - a)^2 sigma^2. With the variance so tied to the pole, the fit
// part's log-likelihood (LR scale) falls short of the free fit's, error
// variance v_free, by min over a of n (ln(p(a) / v_free) + v(a) / p(a) - 1),
// v(a) the fit part's error variance at pole a: the pole that best fits the
// record and the one whose variance matches the declaration are weighed
// together. Taken at the free fit's pole alone, the shortfall was
// n (x - 1 - ln x), x = v_free / p(a_free), which on a long record counts
// the pole's own estimation error as evidence against the declaration (a
// lag of pole 0.545 fitted at 0.518 put the predicted variance 10 % off,
// a shortfall of 9.8 with n = 1954: more than the ln n = 7.6 that leaving
// the variance free costs, so the declaration no longer spoke for the lag).
// The pole is searched over 0-0.95 in steps of 0.05, refined by golden
// section. Nothing where the file declares no variance or the search finds
// no finite shortfall.
std::optional<double> tied_variance_deviance(const Context& cx, std::size_t j, const Vec& wstep, double v_free) {
  const std::optional<double> declared = declared_noise_variance(cx.problem, j);
  if (!declared || !(v_free > 0.0)) return std::nullopt;
  const double sigma2 = *declared, n = static_cast<double>(cx.seg.fit_samples());
  const double v0 = cx.out[j].fit_var;
  const auto shortfall = [&](double a) {
    const double predicted = (1.0 - a) * (1.0 - a) * sigma2;
    Vec wc0 = a * wstep;
    const double v = v0 * std::exp(whitened_objective(cx, j, std::move(wc0), {}) / n);
    return n * (std::log(predicted / v_free) + v / predicted - 1.0);
  };
  std::vector<double> grid;
  for (double a = 0.0; a <= 0.951; a += 0.05) grid.push_back(a);
  const double a = minimise_on_grid(grid, shortfall);
  const double least = shortfall(a);
  if (!std::isfinite(least)) return std::nullopt;
  return std::max(0.0, least);
}

void fit_sensor(const Context& cx, const Hypothesis& h, const Site& s, std::vector<Candidate>& out) {
  const std::size_t j = s.output;
  const RowPrediction row = row_prediction(cx, j);
  const std::vector<Channel>& cs = row.channels;
  const Vec& total = row.total;
  // A transmitter lag S = (1 - a) / (1 - a q^-1) filters everything the
  // sensor sees, the model-predicted part and the disturbances alike: the
  // measured output is x = S x_true, with x = r + G_M u (r the residual, the
  // accepted signals not subtracted when they are refitted jointly). Its
  // one-step prediction error is (1 - a q^-1) x - (1 - a) G_M u, so the
  // correction of r is c = a (x(k-1) - G_M u(k)). A lag on the model's
  // prediction alone would leave the disturbances' part unexplained, and
  // could not tell a sensor from a channel's own lag when one input drives
  // the output; this form does: on a residual without a sensor lag it
  // colours the noise and loses likelihood. The same lag on the
  // disturbances alone is a changed disturbance model, the noise row's
  // candidate, which competes with this one in the selection.
  const OutputState& o = cx.out[j];
  const Vec& r = o.signals.empty() ? o.d : o.base;
  const Index n = r.size();
  Vec step = Vec::Zero(n);  // c / a
  for (Index k = 1; k < n; ++k) step[k] = r[k - 1] + total[k - 1] - total[k];
  const auto fits = [&](double a) { return std::vector<OutputFit>{fit_output(cx, j, Vec(a * step), {})}; };
  // c is linear in a: the search scales the whitened column.
  const Vec wstep = simulate(o.whitener, step);
  const std::vector<double> grid = lag_pole_grid(0.3, 30.0, 16);
  const double a = minimise_on_grid(grid, [&](double v) {
    Vec wc0 = v * wstep;
    return whitened_objective(cx, j, std::move(wc0), {});
  });
  Candidate c = make_candidate(cx, h, cs, fits(a));
  c.tied_variance_deviance = tied_variance_deviance(cx, j, wstep, c.fits[0].fit.fit_var);
  c.finding.nominal = *cx.channel(j, cs[0].input.value());
  c.finding.fitted = series(*cx.channel(j, cs[0].input.value()), unit_lag(a));
  c.finding.parameters["sensor_lag_pole"] = a;
  c.finding.parameters["sensor_time_constant"] = tau_of(a) * cx.problem.sample_time;
  out.push_back(std::move(c));
}

void fit_signal_through_channel(const Context& cx, const Hypothesis& h, const Site& s, std::vector<Candidate>& out) {
  const std::size_t j = s.output;
  const Vec z = cx.extra.col(static_cast<Index>(s.column));
  for (std::size_t i = 0; i < cx.n_in(); ++i) {
    if (!cx.has_channel(j, i)) continue;
    std::vector<OutputFit> f{fit_output(cx, j, Vec(), {simulate(*cx.channel(j, i), z)})};
    DiscreteTf tf = *cx.channel(j, i);
    const double k = f[0].fit.theta(0);
    for (double& b : tf.num) b *= k;
    Candidate c = make_candidate(cx, h, {{j, std::nullopt}}, std::move(f));
    c.finding.signal = cx.problem.extra_names[s.column];
    c.finding.fitted = tf;
    c.facts["through_input"] = static_cast<double>(i);
    c.facts["factor"] = k;
    out.push_back(std::move(c));
  }
}

void fit_signal_fopdt(const Context& cx, const Hypothesis& h, const Site& s, std::vector<Candidate>& out) {
  const std::size_t j = s.output;
  const Vec z = cx.extra.col(static_cast<Index>(s.column));
  const Fopdt fo = best_fopdt(cx, j, z, 0, cx.settings.max_extra_delay, false);
  std::vector<OutputFit> f{fit_output(cx, j, Vec(), {shifted(simulate(unit_lag(fo.pole), z), fo.delay)})};
  const double k = f[0].fit.theta(0);
  DiscreteTf tf;
  tf.num = {k * (1.0 - fo.pole)};
  tf.den = {1.0, -fo.pole};
  tf.delay = fo.delay;
  Candidate c = make_candidate(cx, h, {{j, std::nullopt}}, std::move(f));
  c.finding.signal = cx.problem.extra_names[s.column];
  c.finding.fitted = tf;
  c.facts["gain"] = k;
  c.facts["pole"] = fo.pole;
  out.push_back(std::move(c));
}

void fit_plant_level_gain(const Context& cx, const Hypothesis& h, const Site&, std::vector<Candidate>& out) {
  std::vector<std::size_t> js;
  // Only outputs that several inputs drive: with one input, a gain set by
  // the output's level is that channel's own static map, which the channel
  // form tests against the best linear gain (static_nonlinearity); here it
  // would take two plain gains on two single-input outputs for one
  // nonlinearity.
  for (std::size_t j = 0; j < cx.n_out(); ++j)
    if (row_prediction(cx, j).channels.size() >= 2) js.push_back(j);
  level_gain(cx, h, js, out);
}

}  // namespace mpm::diagnosis
