#include "core/diagnosis.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <exception>
#include <cmath>
#include <limits>
#include <functional>
#include <set>
#include <thread>
#include <stdexcept>

#include "core/chi_square.hpp"
#include "core/diagnosis_context.hpp"
#include "core/noise_filter.hpp"

namespace mpm::diagnosis {

double Candidate::bic(double log_n) const { return lr - params * log_n; }

int Context::response_delay(std::size_t j, std::size_t i) const {
  const DiscreteTf& g = *channel(j, i);
  int leading = 0;
  while (leading < static_cast<int>(g.num.size()) && g.num[static_cast<std::size_t>(leading)] == 0.0) ++leading;
  return g.delay + leading;
}

OutputFit fit_output(const Context& cx, std::size_t j, Vec c0, std::vector<Vec> X) {
  const OutputState& o = cx.out[j];
  OutputFit f;
  f.output = j;
  const bool joint = !o.signals.empty();
  const Vec& w0 = joint ? o.wbase : o.wd;
  // The whitened columns are the only N-long temporaries; the output's own
  // (w0, its whitened signals) are read in place.
  Vec wc0;
  if (c0.size()) {
    wc0 = simulate(o.whitener, c0);
    wc0 = w0 - wc0;  // coefficient-wise, in place
  }
  std::vector<Vec> wx;
  wx.reserve(X.size());
  for (const Vec& x : X) wx.push_back(simulate(o.whitener, x));
  std::vector<const Vec*> regs;
  regs.reserve(X.size() + o.wsignals.size());
  for (const Vec& x : wx) regs.push_back(&x);
  if (joint)
    for (const Vec& s : o.wsignals) regs.push_back(&s);
  f.fit = least_squares_at(c0.size() ? wc0 : w0, regs, cx.seg);
  wc0.resize(0);
  wx.clear();
  f.correction = c0.size() ? c0 : Vec::Zero(o.d.size());
  for (std::size_t l = 0; l < X.size(); ++l) f.correction += f.fit.theta(static_cast<Index>(l)) * X[l];
  f.fixed = std::move(c0);
  f.regressors = std::move(X);
  if (joint) {
    const auto nx = static_cast<Index>(f.regressors.size()), ns = static_cast<Index>(o.signals.size());
    f.signal_theta = f.fit.theta.segment(nx, ns);
    for (Index s = 0; s < ns; ++s)
      f.correction += (f.signal_theta(s) - o.signal_theta(s)) * o.signals[static_cast<std::size_t>(s)];
    f.fit.theta.conservativeResize(nx);
    f.fit.theta_se.conservativeResize(nx);
  }
  return f;
}

void release_series(Candidate& c) {
  for (OutputFit& f : c.fits) {
    f.correction.resize(0);
    f.fixed.resize(0);
    f.regressors.clear();
    f.regressors.shrink_to_fit();
    f.fit.hold_error.resize(0);
  }
}

bool keeps_series(const Context& cx, const Candidate& c) {
  if (cx.keep_series) return true;
  const Candidate* r = cx.rebuilding;
  return r && r->lr == c.lr && r->finding.physics == c.finding.physics && r->params == c.params &&
         r->z_hold == c.z_hold;
}

std::vector<Vec> noise_change_regressors(const Vec& r) { return {shifted(r, 1), shifted(r, 2), shifted(r, 3)}; }

double objective(const Context& cx, const std::vector<OutputFit>& fits) {
  double s = 0.0;
  for (const auto& f : fits) s += std::log(f.fit.fit_var / cx.out[f.output].fit_var);
  return s * static_cast<double>(cx.seg.fit_samples());
}

double objective(const Context& cx, const OutputFit& fit) {
  double s = 0.0;
  s += std::log(fit.fit.fit_var / cx.out[fit.output].fit_var);
  return s * static_cast<double>(cx.seg.fit_samples());
}

Candidate make_candidate(const Context& cx, std::string physics, std::vector<Channel> channels, OutputFit fit,
                         int params) {
  std::vector<OutputFit> fits;
  fits.push_back(std::move(fit));
  return make_candidate(cx, std::move(physics), std::move(channels), std::move(fits), params);
}

void score(const Context& cx, Candidate& c) {
  c.lr = -objective(cx, c.fits);
  // Out of sample: does the (whitened) correction point along the held-out
  // residual? z = <e0, w c> / (sigma0 |w c|), N(0, 1) when c is unrelated to
  // it; and the held-out variance must drop.
  // The variance of <e0, w c> is taken with the autocovariance of the errors
  // the candidate leaves (Bartlett window): they are white when the noise
  // model is right and the candidate explains the mismatch, and then this is
  // sigma0^2 |w c|^2; when the disturbances are coloured beyond what the
  // whitener knows, a slowly varying correction lines up with them by chance
  // far more often, and the test must not take that for evidence.
  constexpr Index kLags = 20;
  const Index nh = cx.out.empty() ? 0 : cx.out[0].d.size();
  // The held-out part as runs of consecutive samples (lags stay inside one).
  std::vector<std::pair<Index, Index>> runs;
  for (Index k = 0; k < nh; ++k) {
    if (!cx.seg.hold[static_cast<std::size_t>(k)]) continue;
    if (runs.empty() || runs.back().second != k) runs.push_back({k, k});
    runs.back().second = k + 1;
  }
  double num = 0.0, var = 0.0;
  c.hold_gain = 0.0;
  std::array<double, kLags + 1> gamma{}, cross{};
  std::array<Index, kLags + 1> pairs{};
  for (const auto& f : c.fits) {
    const OutputState& o = cx.out[f.output];
    const Vec& e1 = f.fit.hold_error;
    const Vec wc = o.hold_error - e1;
    gamma.fill(0.0);
    cross.fill(0.0);
    pairs.fill(0);
    for (const auto& [first, end] : runs)
      for (Index k = first; k < end; ++k) {
        num += o.hold_error(k) * wc(k);
        const Index last = std::min(kLags, end - 1 - k);
        for (Index l = 0; l <= last; ++l) {
          gamma[static_cast<std::size_t>(l)] += e1(k) * e1(k + l);
          cross[static_cast<std::size_t>(l)] += wc(k) * wc(k + l);
          ++pairs[static_cast<std::size_t>(l)];
        }
      }
    for (std::size_t l = 0; l <= static_cast<std::size_t>(kLags); ++l) {
      if (pairs[l] == 0) break;
      const double weight = l == 0 ? 1.0 : 2.0 * (1.0 - static_cast<double>(l) / static_cast<double>(kLags + 1));
      var += weight * gamma[l] / static_cast<double>(pairs[l]) * cross[l];
    }
    c.hold_gain += std::log(o.hold_var / f.fit.hold_var);
  }
  c.z_hold = var > 0.0 ? num / std::sqrt(var) : 0.0;

  // Under feedback G_M u mirrors the disturbances the controller rejects, so
  // a correction built from it can take up a disturbance model that the
  // whitener has wrong. Refitted jointly with an AR(3) change of that model
  // (the lags of the residual the correction leaves, so that they cannot
  // take up the correction itself), a real process change still explains
  // the residual; one that rode on the wrong N does not.
  double beyond = 0.0;
  for (const auto& f : c.fits) {
    const OutputState& o = cx.out[f.output];
    std::vector<Vec> X = f.regressors;
    for (Vec& lag : noise_change_regressors(o.d - f.correction)) X.push_back(std::move(lag));
    beyond += std::log(o.noise_change_var / fit_output(cx, f.output, f.fixed, X).fit.fit_var);
  }
  c.lr_beyond_noise = beyond * static_cast<double>(cx.seg.fit_samples());
}

namespace {

// Whitened variances and held-out errors of output j as it stands: its
// process-corrected residual less the signals-only fit of its accepted
// recorded signals.
void refresh(Context& cx, std::size_t j) {
  OutputState& o = cx.out[j];
  o.wbase = simulate(o.whitener, o.base);
  o.wsignals.resize(o.signals.size());
  for (std::size_t s = 0; s < o.signals.size(); ++s) o.wsignals[s] = simulate(o.whitener, o.signals[s]);
  const LinearFit f = least_squares(o.wbase, o.wsignals, cx.seg);
  o.signal_theta = f.theta;
  o.d = o.base;
  for (std::size_t s = 0; s < o.signals.size(); ++s) o.d -= f.theta(static_cast<Index>(s)) * o.signals[s];
  o.wd = simulate(o.whitener, o.d);
  o.fit_var = f.fit_var;
  o.hold_var = f.hold_var;
  o.hold_error = f.hold_error;
  o.noise_change_var = fit_output(cx, j, Vec(), noise_change_regressors(o.d)).fit.fit_var;
}

std::vector<int> valid_runs(const std::vector<char>& valid) {
  std::vector<int> run(valid.size(), 0);
  for (std::size_t k = 0; k < valid.size(); ++k) run[k] = valid[k] ? (k ? run[k - 1] : 0) + 1 : 0;
  return run;
}

struct LagBlock {
  const Vec* x;
  int first;
  int count;
};

struct Arx {
  std::vector<double> ar;  // 1, -a1, ...
  double rss = 0.0;
  Index rows = 0;
};

// Least squares of d(k) on [1, d(k-1..k-na), blocks] over the fit part.
Arx arx(const Context& cx, const Vec& d, int na, const std::vector<LagBlock>& blocks) {
  const std::vector<int> run = valid_runs(cx.valid);
  int max_lag = na;
  Index cols = 1 + na;
  for (const auto& b : blocks) {
    max_lag = std::max(max_lag, b.first + b.count - 1);
    cols += b.count;
  }
  std::vector<Index> rows;
  for (Index k = cx.seg.begin; k < d.size(); ++k)
    if (cx.seg.fit[static_cast<std::size_t>(k)] && run[static_cast<std::size_t>(k)] > max_lag) rows.push_back(k);
  Arx out;
  out.ar.assign(static_cast<std::size_t>(na) + 1, 0.0);
  out.ar[0] = 1.0;
  if (static_cast<Index>(rows.size()) < 3 * cols) return out;
  Eigen::MatrixXd X(static_cast<Index>(rows.size()), cols);
  Vec y(static_cast<Index>(rows.size()));
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const Index k = rows[r], i = static_cast<Index>(r);
    Index c = 0;
    X(i, c++) = 1.0;
    for (int l = 1; l <= na; ++l) X(i, c++) = d(k - l);
    for (const auto& b : blocks)
      for (int l = b.first; l < b.first + b.count; ++l) X(i, c++) = (*b.x)(k - l);
    y(i) = d(k);
  }
  // Scale columns for conditioning.
  Vec scale = X.colwise().norm().transpose().cwiseMax(1e-300);
  const Eigen::MatrixXd Xs = X * scale.cwiseInverse().asDiagonal();
  const Vec beta = Xs.colPivHouseholderQr().solve(y).cwiseQuotient(scale);
  out.rss = (y - X * beta).squaredNorm();
  out.rows = static_cast<Index>(rows.size());
  for (int l = 1; l <= na; ++l) out.ar[static_cast<std::size_t>(l)] = -beta(l);
  return out;
}

std::vector<LagBlock> input_blocks(const Context& cx, std::size_t j, int nb) {
  std::vector<LagBlock> blocks;
  for (std::size_t i = 0; i < cx.n_in(); ++i) {
    if (!cx.excited[i]) continue;
    const Vec& g = cx.gu[j * cx.n_in() + i];
    if (g.size()) {
      blocks.push_back({&g, 1, nb});
    }
  }
  return blocks;
}

}  // namespace

double signal_granger_lr(const Context& cx, std::size_t j, std::size_t column, int& dof) {
  const int nb = cx.settings.input_lags;
  std::vector<LagBlock> blocks = input_blocks(cx, j, nb);
  // Plain lags of the inputs with no channel (a missing channel).
  std::vector<Vec> plain;
  plain.reserve(cx.n_in());
  for (std::size_t i = 0; i < cx.n_in(); ++i)
    if (cx.excited[i] && !cx.gu[j * cx.n_in() + i].size()) plain.push_back(cx.problem.du.col(static_cast<Index>(i)));
  for (const Vec& p : plain) blocks.push_back({&p, 1, nb});
  const Arx without = arx(cx, cx.out[j].d, cx.settings.ar_order, blocks);
  const Vec z = cx.extra.col(static_cast<Index>(column));
  blocks.push_back({&z, 0, nb});
  const Arx with = arx(cx, cx.out[j].d, cx.settings.ar_order, blocks);
  dof = nb;
  if (with.rows == 0 || with.rss <= 0.0) return 0.0;
  return static_cast<double>(with.rows) * std::log(without.rss / with.rss);
}

namespace {

Context prepare(const Problem& p, const Settings& s) {
  Context cx{p, s, {}, {}, {}, {}, {}, {}};
  const Index n = p.residual.rows();
  std::vector<char> finite(static_cast<std::size_t>(n), 1);
  for (Index k = 0; k < n; ++k) {
    bool ok = p.residual.row(k).allFinite() && p.du.row(k).allFinite();
    if (p.extra.cols()) ok = ok && p.extra.row(k).allFinite();
    finite[static_cast<std::size_t>(k)] = ok && k >= static_cast<Index>(p.begin);
  }
  const std::vector<int> run = valid_runs(finite);
  const int settle = 3 * s.ar_order;
  cx.valid.assign(static_cast<std::size_t>(n), 0);
  Index first = -1;
  for (Index k = 0; k < n; ++k) {
    cx.valid[static_cast<std::size_t>(k)] = run[static_cast<std::size_t>(k)] > settle;
    if (cx.valid[static_cast<std::size_t>(k)] && first < 0) first = k;
  }
  if (first < 0) first = n;
  cx.seg.begin = first;
  // Ten blocks; every third one (30 %) held out.
  cx.seg.fit.assign(static_cast<std::size_t>(n), 0);
  cx.seg.hold.assign(static_cast<std::size_t>(n), 0);
  const Index block = std::max<Index>(1, (n - first) / 10);
  for (Index k = first; k < n; ++k) {
    if (!cx.valid[static_cast<std::size_t>(k)]) continue;
    const bool held = std::min<Index>(9, (k - first) / block) % 3 == 2;
    (held ? cx.seg.hold : cx.seg.fit)[static_cast<std::size_t>(k)] = 1;
    ++(held ? cx.seg.hold_n : cx.seg.fit_n);
  }
  cx.seg.index();

  cx.excited.assign(p.inputs.size(), false);
  for (std::size_t i = 0; i < p.inputs.size(); ++i) {
    const Vec u = p.du.col(static_cast<Index>(i));
    if (cx.seg.fit_n < 10) continue;
    const double sd = std::sqrt(variance(u, cx.seg.fit));
    const double ref = std::max(1.0, u.cwiseAbs().maxCoeff()) * 1e-6;
    cx.excited[i] = sd > ref;
  }
  cx.min_input_delay = 1;
  for (std::size_t j = 0; j < p.outputs.size(); ++j)
    for (std::size_t i = 0; i < p.inputs.size(); ++i)
      if (cx.has_channel(j, i) && cx.response_delay(j, i) == 0) cx.min_input_delay = 0;
  cx.gu.resize(p.outputs.size() * p.inputs.size());
  for (std::size_t j = 0; j < p.outputs.size(); ++j)
    for (std::size_t i = 0; i < p.inputs.size(); ++i)
      if (cx.has_channel(j, i)) cx.gu[j * p.inputs.size() + i] = simulate(*cx.channel(j, i), p.du.col(static_cast<Index>(i)));

  cx.extra = p.extra;
  for (Index c = 0; c < cx.extra.cols(); ++c) {
    double last = 0.0, sum = 0.0;
    Index cnt = 0;
    for (Index k = 0; k < n; ++k) {
      if (std::isfinite(cx.extra(k, c))) last = cx.extra(k, c); else cx.extra(k, c) = last;
      if (cx.seg.fit[static_cast<std::size_t>(k)]) { sum += cx.extra(k, c); ++cnt; }
    }
    cx.extra.col(c).array() -= cnt ? sum / static_cast<double>(cnt) : 0.0;
  }

  cx.out.resize(p.outputs.size());
  for (std::size_t j = 0; j < p.outputs.size(); ++j) {
    OutputState& o = cx.out[j];
    o.d = p.residual.col(static_cast<Index>(j));
    double last = 0.0;
    for (Index k = 0; k < n; ++k) {
      if (std::isfinite(o.d(k))) last = o.d(k); else o.d(k) = last;
    }
    // Remove the fit part's mean: the offset is not a mismatch.
    double sum = 0.0;
    Index cnt = 0;
    for (Index k = cx.seg.begin; k < n; ++k)
      if (cx.seg.fit[static_cast<std::size_t>(k)]) { sum += o.d(k); ++cnt; }
    if (cnt) o.d.array() -= sum / static_cast<double>(cnt);
    if (j < p.noise.size() && p.noise[j]) {
      o.whitener = inverse(*p.noise[j]);
    } else {
      std::vector<LagBlock> blocks = input_blocks(cx, j, s.input_lags);
      std::vector<Vec> extras;
      extras.reserve(static_cast<std::size_t>(cx.extra.cols()));
      for (Index c = 0; c < cx.extra.cols(); ++c) extras.push_back(cx.extra.col(c));
      for (const Vec& z : extras) blocks.push_back({&z, 0, s.input_lags});
      const Arx a = arx(cx, o.d, s.ar_order, blocks);
      o.whitener = DiscreteTf{a.ar, {1.0}, 0};
    }
    o.base = o.d;
    refresh(cx, j);
  }
  return cx;
}

bool overlaps(const std::set<std::pair<std::size_t, long>>& used, const Finding& f) {
  for (const auto& c : f.channels) {
    const long in = c.input ? static_cast<long>(*c.input) : -1;
    if (in >= 0 && used.count({c.output, in})) return true;
  }
  return false;
}

// The generator calls of one round, in order: each candidate is tagged with
// its call and its rank in it, so that the chosen one can be rebuilt with its
// columns (the search keeps only numbers: Context::keep_series). The calls
// only read the context, so those queued since the last flush run on
// Settings::threads threads; their candidates are appended in call order,
// whatever the threads did first.
using Group = std::function<void(std::vector<Candidate>&)>;
struct Groups {
  std::vector<Group> calls;
  std::size_t flushed = 0;
  void add(Group g) { calls.push_back(std::move(g)); }
  void flush(std::vector<Candidate>& all, std::size_t threads) {
    const std::size_t first = flushed, count = calls.size() - flushed;
    flushed = calls.size();
    std::vector<std::vector<Candidate>> got(count);
    std::vector<std::exception_ptr> failed(count);
    std::atomic<std::size_t> next{0};
    const auto work = [&] {
      for (std::size_t g = next++; g < count; g = next++) try {
          calls[first + g](got[g]);
        } catch (...) {
          failed[g] = std::current_exception();
        }
    };
    std::vector<std::thread> pool;
    for (std::size_t t = 1; t < std::min(threads, count); ++t) pool.emplace_back(work);
    work();
    for (std::thread& t : pool) t.join();
    for (std::size_t g = 0; g < count; ++g) {
      if (failed[g]) std::rethrow_exception(failed[g]);
      for (std::size_t k = 0; k < got[g].size(); ++k) {
        got[g][k].group = first + g;
        got[g][k].rank = k;
        all.push_back(std::move(got[g][k]));
      }
    }
  }
};

// The chosen candidate again, its generator rerun keeping its columns only:
// the fits are deterministic, so it is the same candidate.
Candidate rebuild_chosen(Context& cx, const Groups& groups, const Candidate& chosen) {
  const bool keep = cx.keep_series;
  cx.keep_series = false;
  cx.rebuilding = &chosen;
  std::vector<Candidate> again;
  groups.calls.at(chosen.group)(again);
  cx.rebuilding = nullptr;
  cx.keep_series = keep;
  if (again.size() <= chosen.rank || again[chosen.rank].lr != chosen.lr ||
      again[chosen.rank].finding.physics != chosen.finding.physics)
    throw std::logic_error("diagnosis: the chosen candidate did not rebuild the same");
  Candidate c = std::move(again[chosen.rank]);
  c.group = chosen.group;
  c.rank = chosen.rank;
  return c;
}

std::vector<Candidate> generate(const Context& cx, const std::set<std::pair<std::size_t, long>>& used,
                                const std::set<std::pair<std::size_t, std::size_t>>& used_signals, Groups& groups,
                                Progress progress) {
  std::vector<Candidate> all;
  for (std::size_t j = 0; j < cx.n_out(); ++j)
    for (std::size_t i = 0; i < cx.n_in(); ++i)
      if (!used.count({j, static_cast<long>(i)}))
        groups.add([&cx, j, i](std::vector<Candidate>& o) { channel_hypotheses(cx, j, i, o); });
  groups.flush(all, cx.settings.threads);
  if (progress) progress("channel hypotheses fitted");
  for (std::size_t i = 0; i < cx.n_in(); ++i)
    groups.add([&cx, i](std::vector<Candidate>& o) { column_hypotheses(cx, i, o); });
  for (std::size_t j = 0; j < cx.n_out(); ++j)
    groups.add([&cx, j](std::vector<Candidate>& o) { row_hypotheses(cx, j, o); });
  groups.add([&cx](std::vector<Candidate>& o) { plant_hypotheses(cx, o); });
  groups.flush(all, cx.settings.threads);
  if (progress) progress("column and row hypotheses fitted");
  // A loose screen (5 %, plain lags have little power on slow responses):
  // the decision is the structured fit's own test below, Bonferroni-corrected.
  const double pre = chi_square_quantile_upper(0.05, cx.settings.input_lags);
  for (std::size_t j = 0; j < cx.n_out(); ++j)
    for (Index c = 0; c < cx.extra.cols(); ++c) {
      if (used_signals.count({j, static_cast<std::size_t>(c)})) continue;
      int dof = 0;
      const double lr = signal_granger_lr(cx, j, static_cast<std::size_t>(c), dof);
      if (cx.settings.verbose && progress)
        progress(("  Granger test of " + cx.problem.extra_names[static_cast<std::size_t>(c)] + " -> " +
                  cx.problem.outputs[j] + ": LR " + fmt(lr, 4) + " (limit " + fmt(pre, 3) + ")").c_str());
      if (lr > pre)
        groups.add([&cx, j, c](std::vector<Candidate>& o) { signal_hypotheses(cx, j, static_cast<std::size_t>(c), o); });
    }
  groups.flush(all, cx.settings.threads);
  std::vector<Candidate> keep;
  for (auto& c : all)
    if (!overlaps(used, c.finding)) keep.push_back(std::move(c));
  return keep;
}

// The fit-part test and the held-out test are independent under "no
// mismatch", so a candidate passes both with probability (fit level) x
// (held-out level): the fit level is alpha / hold level, shared over the family.
double fit_level(const Settings& s, double family) { return s.alpha / s.holdout_level / family; }

// A recorded signal is not moved by the controller, so it is not held to
// the test against a changed disturbance model (see score()).
bool passes(const Candidate& c, const Settings& s, double family) {
  return c.lr >= chi_square_quantile_upper(fit_level(s, family), c.params) && c.z_hold >= s.holdout_z &&
         c.hold_gain > 0.0 && (c.finding.signal || c.lr_beyond_noise >= chi_square_quantile_upper(s.alpha, c.params));
}

// Which of the candidates that pass is taken: BIC on the fit part plus the
// log-likelihood gain on the held-out part, which the fit never saw (so it
// needs no penalty). Two hypotheses that fit the fit part alike (a slower
// channel and a smaller gain look alike where the inputs move slowly) are
// told apart by the data that judged neither.
double selection_score(const Context& cx, const Candidate& c, double log_n) {
  return c.bic(log_n) + static_cast<double>(cx.seg.hold_samples()) * c.hold_gain;
}

// The fit block: one-step prediction-error variances (the whitened residual
// the fit minimises), summed over the finding's outputs. The raw residual's
// variance is no measure of fit in closed loop (feedback correlates dG u
// with the disturbance, so a correct correction can raise it); it is kept
// in `raw` for the record.
FitNumbers fit_numbers(const Context& cx, const Candidate& c, FitNumbers& raw) {
  FitNumbers f;
  for (const auto& of : c.fits) {
    const OutputState& o = cx.out[of.output];
    f.residual_variance_before += o.fit_var;
    f.residual_variance_after += of.fit.fit_var;
    f.holdout_variance_before += o.hold_var;
    f.holdout_variance_after += of.fit.hold_var;
    const Vec after = o.d - of.correction;
    raw.residual_variance_before += variance(o.d, cx.seg.fit);
    raw.residual_variance_after += variance(after, cx.seg.fit);
    raw.holdout_variance_before += variance(o.d, cx.seg.hold);
    raw.holdout_variance_after += variance(after, cx.seg.hold);
  }
  return f;
}

void disturbance_models(Context& cx, const std::vector<bool>& explained, Result& r) {
  const Index n_fit = cx.seg.fit_samples();
  for (std::size_t j = 0; j < cx.n_out(); ++j) {
    if (explained[j] || j >= cx.problem.noise.size() || !cx.problem.noise[j]) continue;
    const OutputState& o = cx.out[j];
    // Corrections C = num / den of the whitened residual N^-1 d (the new
    // disturbance model is N / C): AR(1..3), and ARMA(1,1). A first-order N
    // whose pole moved leaves N^-1 d = (1 - p q^-1) / (1 - p' q^-1) a, a pole
    // and zero that nearly cancel: low-order AR fits take it up poorly, the
    // ARMA(1,1) exactly (den pole on a grid, num by least squares).
    std::vector<DiscreteTf> corrections;
    for (int k = 1; k <= 3; ++k) corrections.push_back(DiscreteTf{fit_ar(o.wd, cx.seg.fit, k), {1.0}, 0});
    const auto arma = [&](double b) {
      const Vec v = simulate(DiscreteTf{{1.0}, {1.0, -b}, 0}, o.wd);
      return DiscreteTf{fit_ar(v, cx.seg.fit, 1), {1.0, -b}, 0};
    };
    std::vector<double> poles;
    for (int k = -6; k <= 14; ++k) poles.push_back(k < 0 ? 0.15 * k : 1.0 - std::pow(0.7, k + 1));
    const double b = minimise_on_grid(poles, [&](double v) {
      return least_squares(simulate(arma(v), o.wd), {}, cx.seg).fit_var;
    });
    corrections.push_back(arma(b));
    const double limit_alpha = fit_level(cx.settings, static_cast<double>(corrections.size() * cx.n_out()));
    std::optional<Candidate> best;
    DiscreteTf best_correction;
    for (const DiscreteTf& correction : corrections) {
      const int params = static_cast<int>(correction.den.size() > 1 ? 2 : correction.num.size() - 1);
      const LinearFit f = least_squares(simulate(correction, o.wd), {}, cx.seg);
      Candidate c;
      OutputFit of;
      of.output = j;
      of.correction = Vec::Zero(o.d.size());
      of.fit = f;
      c.fits.push_back(std::move(of));
      c.params = params;
      score(cx, c);
      if (c.lr < chi_square_quantile_upper(limit_alpha, params) || c.z_hold < cx.settings.holdout_z || c.hold_gain <= 0.0)
        continue;
      if (!best || c.bic(std::log(static_cast<double>(n_fit))) > best->bic(std::log(static_cast<double>(n_fit)))) {
        best = std::move(c);
        best_correction = correction;
      }
    }
    if (!best) continue;
    Finding f;
    f.channels = {{j, std::nullopt}};
    f.physics = "disturbance_model";
    const DiscreteTf& nn = *cx.problem.noise[j];
    f.nominal = nn;
    DiscreteTf fitted = nn;
    fitted.num = poly_mul(nn.num, best_correction.den);
    fitted.den = poly_mul(nn.den, best_correction.num);
    f.fitted = fitted;
    const double a_var = best->fits[0].fit.fit_var;
    f.parameters["variance"] = a_var;
    f.lr = best->lr;
    f.params = best->params;
    f.summary = "no input or recorded signal explains " + cx.problem.outputs[j] +
                "'s residual, but its one-step prediction error is " + fmt(100.0 * (1.0 - a_var / o.fit_var), 2) +
                " % smaller with a changed disturbance model (" +
                (best_correction.den.size() > 1 ? std::string("ARMA(1,1)")
                                                 : "AR order " + std::to_string(best->params)) +
                " on N^-1 d)";
    // Fit numbers: one-step prediction-error variances (the process model is unchanged).
    f.fit.residual_variance_before = o.fit_var;
    f.fit.residual_variance_after = a_var;
    f.fit.holdout_variance_before = o.hold_var;
    f.fit.holdout_variance_after = best->fits[0].fit.hold_var;
    const double v = variance(o.d, cx.seg.fit);
    const double h = variance(o.d, cx.seg.hold);
    f.raw = {v, v, h, h};
    r.findings.push_back(std::move(f));
  }
}

}  // namespace

Result diagnose(const Problem& problem, const Settings& settings, Progress progress) {
  Result r;
  Context cx = prepare(problem, settings);
  if (cx.seg.fit_samples() < 200 || cx.seg.hold_samples() < 100) {
    r.notes.push_back("too few usable samples to fit hypotheses");
    for (bool f : problem.monitor_flag) r.mismatch = r.mismatch || f;
    return r;
  }
  for (std::size_t i = 0; i < cx.n_in(); ++i)
    if (!cx.excited[i]) r.notes.push_back("input " + problem.inputs[i] + " does not move: its channels are not analysed");

  std::set<std::pair<std::size_t, long>> used;
  std::set<std::pair<std::size_t, std::size_t>> used_signals;
  std::vector<bool> explained(cx.n_out(), false);
  double family = 0.0;
  const double log_n = std::log(static_cast<double>(cx.seg.fit_samples()));
  for (int round = 0; round < settings.max_findings; ++round) {
    Groups groups;
    cx.keep_series = false;
    std::vector<Candidate> cands = generate(cx, used, used_signals, groups, progress);
    cx.keep_series = true;
    if (round == 0) family = std::max<double>(1.0, static_cast<double>(cands.size()));
    // A recorded signal that explains the residual goes first: while it is
    // in the residual, the controller moves the inputs to cancel it and any
    // fit of the process channels is biased towards explaining it.
    bool signal_first = false;
    for (const auto& c : cands) signal_first = signal_first || (c.finding.signal && passes(c, settings, family));
    const Candidate* best = nullptr;
    double best_score = -std::numeric_limits<double>::infinity();
    for (const auto& c : cands) {
      if (settings.verbose && progress) {
        std::string m = "  candidate " + c.finding.physics + " [";
        for (const auto& ch : c.finding.channels)
          m += problem.outputs[ch.output] + "<-" + (ch.input ? problem.inputs[*ch.input] : c.finding.signal.value_or("-")) + " ";
        m += "] lr " + fmt(c.lr, 4) + " (limit " + fmt(chi_square_quantile_upper(fit_level(settings, family), c.params), 3) +
             ") z_hold " + fmt(c.z_hold, 3) + " bic " + fmt(c.bic(log_n), 4) + " selection " +
             fmt(selection_score(cx, c, log_n), 4) + ": " + c.finding.summary;
        progress(m.c_str());
      }
      if (!passes(c, settings, family) || (signal_first && !c.finding.signal)) continue;
      const double score_c = selection_score(cx, c, log_n);
      if (score_c > best_score) {
        best_score = score_c;
        best = &c;
      }
    }
    if (!best) break;
    const Candidate chosen = rebuild_chosen(cx, groups, *best);
    best = &chosen;
    Finding f = best->finding;
    f.fit = fit_numbers(cx, *best, f.raw);
    for (const auto& ch : f.channels) {
      if (ch.input) used.insert({ch.output, static_cast<long>(*ch.input)});
      explained[ch.output] = true;
    }
    if (f.signal)
      for (std::size_t c = 0; c < problem.extra_names.size(); ++c)
        if (problem.extra_names[c] == *f.signal) used_signals.insert({f.channels[0].output, c});
    for (const auto& of : best->fits) {
      // The finding's own correction leaves the residual; a recorded signal
      // instead joins the output's free signal regressors.
      OutputState& o = cx.out[of.output];
      Vec own = of.correction;
      for (Index s = 0; s < of.signal_theta.size(); ++s)
        own -= (of.signal_theta(s) - o.signal_theta(s)) * o.signals[static_cast<std::size_t>(s)];
      if (f.signal) {
        for (std::size_t l = 0; l < of.regressors.size(); ++l) {
          own -= of.fit.theta(static_cast<Index>(l)) * of.regressors[l];
          o.signals.push_back(of.regressors[l]);
        }
      }
      o.base -= own;
      refresh(cx, of.output);
    }
    r.findings.push_back(std::move(f));
    if (progress) progress(("accepted: " + r.findings.back().summary).c_str());
  }
  disturbance_models(cx, explained, r);
  for (std::size_t j = 0; j < cx.n_out(); ++j) {
    if (j < problem.monitor_flag.size() && problem.monitor_flag[j] && !explained[j]) {
      bool any = false;
      for (const auto& f : r.findings)
        for (const auto& c : f.channels) any = any || c.output == j;
      if (any) continue;
      Finding f;
      f.physics = "other";
      if (j < problem.monitor_located.size())
        for (std::size_t i : problem.monitor_located[j]) f.channels.push_back({j, i});
      if (f.channels.empty()) f.channels.push_back({j, std::nullopt});
      f.summary = "the Granger test locates a mismatch in " + problem.outputs[j] +
                  " that none of the structured hypotheses explains significantly";
      const double v = variance(cx.out[j].d, cx.seg.fit);
      const double h = variance(cx.out[j].d, cx.seg.hold);
      f.fit = {v, v, h, h};
      f.raw = f.fit;
      r.findings.push_back(std::move(f));
    }
  }
  r.mismatch = !r.findings.empty();
  for (bool f : problem.monitor_flag) r.mismatch = r.mismatch || f;
  return r;
}

}  // namespace mpm::diagnosis
