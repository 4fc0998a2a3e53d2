// Record preparation for the diagnosis: which samples are usable, the
// fit / held-out blocks, the inputs that move, each channel's G_ji du_i, and
// each output's residual with its whitener (N^-1 when the plant file gives
// N, else the AR part of an ARX fit with the inputs in the regression). Also
// the Granger screen of recorded signals, which uses the same ARX fit.
#include <algorithm>
#include <cmath>

#include "core/diagnosis_context.hpp"
#include "core/noise_filter.hpp"

namespace mpm::diagnosis {

int Context::response_delay(std::size_t j, std::size_t i) const {
  const DiscreteTf& g = *channel(j, i);
  int leading = 0;
  while (leading < static_cast<int>(g.num.size()) && g.num[static_cast<std::size_t>(leading)] == 0.0) ++leading;
  return g.delay + leading;
}

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
  o.cv_var = f.cv_var;
  o.fold_var = f.fold_var;
  o.hold_error = f.hold_error;
  o.noise_change_var = fit_output(cx, j, Vec(), noise_change_regressors(o.d)).fit.fit_var;
}

namespace {

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
  // Ten blocks; every third one (30 %) held out, from Settings::holdout_phase on.
  cx.seg.fit.assign(static_cast<std::size_t>(n), 0);
  cx.seg.hold.assign(static_cast<std::size_t>(n), 0);
  cx.seg.fold.assign(static_cast<std::size_t>(n), -1);
  const Index block = std::max<Index>(1, (n - first) / 10);
  for (Index k = first; k < n; ++k) {
    if (!cx.valid[static_cast<std::size_t>(k)]) continue;
    // The thirds of the blocks are the folds of the cross-fitted check.
    const auto third = static_cast<signed char>(std::min<Index>(9, (k - first) / block) % 3);
    cx.seg.fold[static_cast<std::size_t>(k)] = third;
    const bool held = third == s.holdout_phase;
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
      // And each recorded signal through each of the output's channels, as
      // the inputs are: a signal that enters with an input (a heater's
      // disturbance) acts through a channel far slower than its plain lags
      // reach: without these columns the AR part is fitted with the
      // signal's slow response unexplained, and on the real TCLab runs a
      // heater disturbance of 20 % (13 degrees on T1) came out at LR 1.
      std::vector<Vec> through;
      through.reserve(extras.size() * cx.n_in());
      for (const Vec& z : extras)
        for (std::size_t i = 0; i < cx.n_in(); ++i)
          if (cx.has_channel(j, i)) through.push_back(simulate(*cx.channel(j, i), z));
      for (const Vec& z : through) blocks.push_back({&z, 0, 2});
      const Arx a = arx(cx, o.d, s.ar_order, blocks);
      o.whitener = DiscreteTf{a.ar, {1.0}, 0};
    }
    o.base = o.d;
    refresh(cx, j);
  }
  return cx;
}

}  // namespace mpm::diagnosis
