// The channel hypotheses of the diagnosis (one output, one input): each is a
// change of the nominal model with one to three physical parameters, fitted
// by prediction-error minimisation of the whitened residual on the fit part
// of the record. Their rows are in diagnosis_table.cpp, their sentences in
// diagnosis_summary.cpp.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "core/diagnosis_table.hpp"

namespace mpm::diagnosis {
namespace {

// G with its slowest pole p replaced by p2; gain_scale multiplies num.
DiscreteTf move_pole(const DiscreteTf& g, double p, double p2, double gain_scale) {
  DiscreteTf out = g;
  out.den = poly_mul(deflate(g.den, p), {1.0, -p2});
  for (double& b : out.num) b *= gain_scale;
  return out;
}

}  // namespace

void fit_gain(const Context& cx, const Hypothesis& h, const Site& s, std::vector<Candidate>& out) {
  const std::size_t j = s.output, i = s.input;
  const Vec& x = cx.gu[j * cx.n_in() + i];
  OutputFit f = fit_output(cx, j, Vec(), {x});
  const double k = 1.0 + f.fit.theta(0), se = f.fit.theta_se(0);
  Candidate c = make_candidate(cx, h, {{j, i}}, {std::move(f)});
  const DiscreteTf& g = *cx.channel(j, i);
  DiscreteTf fitted = g;
  for (double& b : fitted.num) b *= k;
  c.finding.nominal = g;
  c.finding.fitted = fitted;
  c.finding.parameters["gain_factor"] = k;
  c.facts["gain_factor_se"] = se;
  out.push_back(std::move(c));
}

void fit_dead_time(const Context& cx, const Hypothesis& h, const Site& site, std::vector<Candidate>& out) {
  const std::size_t j = site.output, i = site.input;
  const Vec& x = cx.gu[j * cx.n_in() + i];
  const DiscreteTf& g = *cx.channel(j, i);
  int best = 0;
  double best_obj = std::numeric_limits<double>::infinity();
  // Shorter down to the model's own delay (never below the recording's
  // fewest samples an input needs to act), or longer; both ways within the
  // search range, so a model delay of thousands of samples costs no more
  // fits than a short one.
  const int shortest = std::max({-g.delay, cx.min_input_delay - cx.response_delay(j, i),
                                 -cx.settings.max_extra_delay});
  // The delay and the whitener commute: the search shifts the whitened column.
  const Vec wx = simulate(cx.out[j].whitener, x);
  for (int s = shortest; s <= cx.settings.max_extra_delay; ++s) {
    if (s == 0) continue;
    Vec wc0 = shifted(wx, s) - wx;
    const double o = whitened_objective(cx, j, std::move(wc0), {});
    if (o < best_obj) {
      best_obj = o;
      best = s;
    }
  }
  if (best == 0) return;
  Candidate c = make_candidate(cx, h, {{j, i}}, {fit_output(cx, j, shifted(x, best) - x, {})});
  DiscreteTf fitted = g;
  fitted.delay += best;
  c.finding.nominal = g;
  c.finding.fitted = fitted;
  c.finding.parameters["extra_delay_samples"] = best;
  out.push_back(std::move(c));
}

void fit_time_constant(const Context& cx, const Hypothesis& h, const Site& s, std::vector<Candidate>& out) {
  const std::size_t j = s.output, i = s.input;
  const DiscreteTf& g = *cx.channel(j, i);
  const double p = slowest_pole(g);
  const Vec& x = cx.gu[j * cx.n_in() + i];
  const Vec u = cx.problem.du.col(static_cast<Index>(i));
  const double tau = tau_of(p);
  const auto moved = [&](double log_ratio) {
    const double p2 = std::exp(-1.0 / (tau * std::exp(log_ratio)));
    return move_pole(g, p, p2, (1.0 - p2) / (1.0 - p));
  };
  auto corr = [&](double log_ratio) { return Vec(simulate(moved(log_ratio), u) - x); };
  // The search whitens in series with the moved channel: one pass a point.
  const DiscreteTf& whitener = cx.out[j].whitener;
  const Vec wx = simulate(whitener, x);
  const auto search = [&](double log_ratio) {
    Vec wc0 = simulate(series(whitener, moved(log_ratio)), u) - wx;
    return whitened_objective(cx, j, std::move(wc0), {});
  };
  std::vector<double> grid;
  for (int k = 0; k <= 16; ++k) grid.push_back(std::log(0.25) + k * (std::log(4.0) - std::log(0.25)) / 16.0);
  const double lr = minimise_on_grid(grid, search);
  const double p2 = std::exp(-1.0 / (tau * std::exp(lr)));
  Candidate c = make_candidate(cx, h, {{j, i}}, {fit_output(cx, j, corr(lr), {})});
  c.finding.nominal = g;
  c.finding.fitted = move_pole(g, p, p2, (1.0 - p2) / (1.0 - p));
  c.finding.parameters["time_constant_ratio"] = std::exp(lr);
  c.facts["nominal_time_constant_samples"] = tau;
  out.push_back(std::move(c));
}

void fit_extra_lag(const Context& cx, const Hypothesis& h, const Site& s, std::vector<Candidate>& out) {
  const std::size_t j = s.output, i = s.input;
  const DiscreteTf& g = *cx.channel(j, i);
  const Vec& x = cx.gu[j * cx.n_in() + i];
  const double tau_nom = std::max(2.0, tau_of(slowest_pole(g)));
  const auto grid = lag_pole_grid(0.3, tau_nom, 16);
  auto corr = [&](double a) { return Vec(simulate(unit_lag(a), x) - x); };
  // The lag and the whitener commute: the search lags the whitened column.
  const Vec wx = simulate(cx.out[j].whitener, x);
  const double a = minimise_on_grid(grid, [&](double v) {
    Vec wc0 = simulate(unit_lag(v), wx) - wx;
    return whitened_objective(cx, j, std::move(wc0), {});
  });
  if (a <= 0.0) return;
  Candidate c = make_candidate(cx, h, {{j, i}}, {fit_output(cx, j, corr(a), {})});
  c.finding.nominal = g;
  c.finding.fitted = series(g, unit_lag(a));
  c.finding.parameters["extra_lag_pole"] = a;
  out.push_back(std::move(c));
}

void fit_integrator(const Context& cx, const Hypothesis& h, const Site& s, std::vector<Candidate>& out) {
  const std::size_t j = s.output, i = s.input;
  const DiscreteTf& g = *cx.channel(j, i);
  // Where the channel has a slow mode, the plant integrates in its place
  // (its slowest pole moved to 1, the slope of its first moments kept);
  // where it has none (a fast or static channel), the plant is the channel
  // followed by an integrator (per sample, 1 / (1 - q^-1)).
  const double p = slowest_pole(g);
  const bool replaces_pole = p >= 0.5;
  const auto integrating = [&](double gain) {
    if (replaces_pole) return move_pole(g, p, 1.0, gain);
    DiscreteTf with_integrator = series(g, DiscreteTf{{1.0}, {1.0, -1.0}, 0});
    for (double& b : with_integrator.num) b *= gain;
    return with_integrator;
  };
  const DiscreteTf gi = integrating(1.0);
  const Vec xi = simulate(gi, cx.problem.du.col(static_cast<Index>(i)));
  // An integrating plant holds still only at its own balance input, which
  // the self-regulating model's operating point need not be: under
  // feedback the controller finds it, and the integrator sees u - u_b, not
  // u - u0. So the balance offset is a second parameter (the channel's
  // response to a constant, a ramp): without it any offset integrates into
  // a drift that no gain can fit.
  const Vec ramp = simulate(gi, Vec::Ones(xi.size()));
  const Vec& x = cx.gu[j * cx.n_in() + i];
  OutputFit f = fit_output(cx, j, -x, {xi, ramp});
  const double k = f.fit.theta(0);
  const double balance = k != 0.0 ? -f.fit.theta(1) / k : 0.0;
  Candidate c = make_candidate(cx, h, {{j, i}}, {std::move(f)});
  c.finding.nominal = g;
  c.finding.fitted = integrating(k);
  c.finding.parameters["integrator_gain_per_sample"] = k * g.dc_gain() * (replaces_pole ? 1.0 - p : 1.0);
  c.finding.parameters["balance_input_offset"] = balance;
  c.facts["gain_ratio"] = k;
  if (replaces_pole) c.facts["replaced_pole"] = p;
  out.push_back(std::move(c));
}

Fopdt best_fopdt(const Context& cx, std::size_t j, const Vec& x, int min_delay, int max_delay, bool refine_pole) {
  Fopdt best;
  double best_obj = std::numeric_limits<double>::infinity();
  std::vector<double> poles{0.0};
  for (double a : lag_pole_grid(0.5, 200.0, 14)) poles.push_back(a);
  // The lag, the delay and the whitener commute: each pole lags the
  // whitened input once, and each delay shifts that.
  const Vec wx = simulate(cx.out[j].whitener, x);
  for (double a : poles) {
    const Vec lagged = simulate(unit_lag(a), wx);
    for (int d = min_delay; d <= max_delay; ++d) {
      const Vec regressor = shifted(lagged, d);
      const double o = whitened_objective(cx, j, Vec(), {&regressor});
      if (o < best_obj) {
        best_obj = o;
        best = {a, d};
      }
    }
  }
  if (!refine_pole) return best;
  std::vector<double> fine;
  const double t0 = std::max(0.3, tau_of(best.pole));
  for (int k = -4; k <= 4; ++k) fine.push_back(std::exp(-1.0 / (t0 * std::pow(1.35, k))));
  if (best.pole == 0.0) fine.insert(fine.begin(), 0.0);
  best.pole = minimise_on_grid(fine, [&](double a) {
    const Vec regressor = shifted(simulate(unit_lag(a), wx), best.delay);
    return whitened_objective(cx, j, Vec(), {&regressor});
  });
  return best;
}

void fit_missing_channel(const Context& cx, const Hypothesis& h, const Site& s, std::vector<Candidate>& out) {
  const std::size_t j = s.output, i = s.input;
  const Vec u = cx.problem.du.col(static_cast<Index>(i));
  const Fopdt f = best_fopdt(cx, j, u, cx.min_input_delay, 20, true);
  OutputFit fit = fit_output(cx, j, Vec(), {shifted(simulate(unit_lag(f.pole), u), f.delay)});
  const double k = fit.fit.theta(0);
  Candidate c = make_candidate(cx, h, {{j, i}}, {std::move(fit)});
  DiscreteTf nominal;
  if (cx.channel(j, i)) nominal = *cx.channel(j, i);
  DiscreteTf fitted;
  fitted.num = {k * (1.0 - f.pole)};
  fitted.den = {1.0, -f.pole};
  fitted.delay = f.delay;
  c.finding.nominal = nominal;
  c.finding.fitted = fitted;
  c.facts["gain"] = k;
  c.facts["pole"] = f.pole;
  out.push_back(std::move(c));
}

std::vector<double> lag_pole_grid(double tau_lo, double tau_hi, int points) {
  std::vector<double> g;
  for (int k = 0; k < points; ++k) {
    const double t = tau_lo * std::pow(tau_hi / tau_lo, static_cast<double>(k) / (points - 1));
    g.push_back(std::exp(-1.0 / t));
  }
  return g;
}

std::string fmt(double v, int digits) {
  char b[64];
  std::snprintf(b, sizeof b, "%.*g", digits, v);
  return b;
}

double tau_of(double pole) { return pole > 0.0 && pole < 1.0 ? -1.0 / std::log(pole) : 0.0; }

}  // namespace mpm::diagnosis
