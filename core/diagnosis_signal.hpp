// Signal helpers for the offline diagnosis (`mpm diagnose`): whole-record
// filtering, polynomial algebra on channels, input nonlinearities, and the
// least-squares fit of a whitened residual. Offline code: allocation allowed.
#pragma once

#include <algorithm>
#include <cstddef>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "core/transfer_function.hpp"

namespace mpm::diagnosis {

using Vec = Eigen::VectorXd;
using Index = Eigen::Index;

// Which samples a fit may use and which are kept back to judge it:
// interleaved blocks, so that the held-out part sees the same operating
// conditions (a contiguous tail can be a part where nothing moves).
struct Segments {
  std::vector<char> fit;    // per sample: used for fitting
  std::vector<char> hold;   // per sample: held out
  Index begin = 0;          // first usable sample
  Index fit_n = 0;
  Index hold_n = 0;
  // The masks as runs of consecutive samples [first, end), from `begin` on:
  // the fits sum over these (vector operations on contiguous memory). Filled
  // by index() once the masks are set; a fit on an unindexed Segments
  // builds them itself.
  std::vector<std::pair<Index, Index>> fit_runs;
  std::vector<std::pair<Index, Index>> hold_runs;
  // The folds of the cross-fitted check (LinearFit::cv_var): per sample its
  // fold, -1 where the sample is unused; the held-out part is one fold, the
  // fit part the others. Empty: no folds (cv_var is then hold_var).
  std::vector<signed char> fold;
  std::vector<std::vector<std::pair<Index, Index>>> fold_runs;  // per fold, filled by index()
  bool indexed = false;
  void index();
  Index fit_samples() const { return fit_n; }
  Index hold_samples() const { return hold_n; }
};

// tf applied to x from rest (x must be finite): bit for bit what
// DiscreteFilter::step gives from reset(0), at a cost independent of the delay.
Vec simulate(const DiscreteTf& tf, const Vec& x);
// x(k - lag) with zeros before the start (lag may be negative: an advance).
Vec shifted(const Vec& x, int lag);
// Effective input of a valve with backlash of total width `width`.
Vec backlash(const Vec& u, double width);
Vec clipped(const Vec& u, double lo, double hi);

// Polynomial product (ascending powers of q^-1).
std::vector<double> poly_mul(const std::vector<double>& a, const std::vector<double>& b);
// Cascade of two channels.
DiscreteTf series(const DiscreteTf& a, const DiscreteTf& b);
// Unit-gain first-order lag (1 - a) / (1 - a q^-1).
DiscreteTf unit_lag(double pole);
// The real pole of largest magnitude below 1 (the slowest stable mode), 0 when
// the channel is static. Found from the companion matrix of den.
double slowest_pole(const DiscreteTf& tf);
// den / (1 - p q^-1) when p is a root of den (remainder dropped).
std::vector<double> deflate(const std::vector<double>& den, double p);

// Least-squares AR(order) polynomial A(q) = 1 - a_1 q^-1 - ... fitted to x on
// the samples of `mask` (with an intercept).
std::vector<double> fit_ar(const Vec& x, const std::vector<char>& mask, int order);

// Variance about the mean of x over the samples of `mask`.
double variance(const Vec& x, const std::vector<char>& mask);

// Result of regressing a whitened target on whitened regressors plus an
// intercept, fitted on the fit part only.
struct LinearFit {
  Vec theta;               // one per regressor (intercept not included)
  Vec theta_se;            // standard errors of theta
  double fit_var = 0.0;    // error variance on the fit part
  double hold_var = 0.0;   // error variance on the held-out part (about its own mean)
  Vec hold_error;          // full length: mean-removed errors on held-out samples, 0 elsewhere
  // Cross-fitted error variance: each fold of Segments::fold predicted by the
  // fit on the other folds, about the fold's own mean, pooled over the folds
  // (the held-out fold's errors are hold_error's: its other folds are the fit
  // part). Every usable sample is judged out of sample, so an effect that
  // comes in episodes is judged wherever its episodes fall.
  double cv_var = 0.0;
  Vec fold_var;  // per fold, its part of cv_var (0 for a fold too small to judge); empty without folds
};
// Part::fit: the fit part only (theta and fit_var; no held-out errors), for
// the objective of a search.
enum class Part { fit, fit_and_holdout };
LinearFit least_squares(const Vec& target, const std::vector<Vec>& regressors, const Segments& seg,
                        Part part = Part::fit_and_holdout);
// The same on regressors held elsewhere (no copies of N-long columns).
LinearFit least_squares_at(const Vec& target, const std::vector<const Vec*>& regressors, const Segments& seg,
                           Part part = Part::fit_and_holdout);

// Minimises f over a grid and refines the best point by golden section
// between its neighbours. Returns the argument.
template <typename F>
double minimise_on_grid(const std::vector<double>& grid, F&& f) {
  std::size_t best = 0;
  std::vector<double> v(grid.size());
  for (std::size_t g = 0; g < grid.size(); ++g) {
    v[g] = f(grid[g]);
    if (v[g] < v[best]) best = g;
  }
  if (grid.size() < 3) return grid[best];
  double lo = grid[best == 0 ? 0 : best - 1], hi = grid[best + 1 == grid.size() ? best : best + 1];
  const double r = 0.6180339887498949;
  double x1 = hi - r * (hi - lo), x2 = lo + r * (hi - lo);
  double f1 = f(x1), f2 = f(x2);
  for (int it = 0; it < 14; ++it) {
    if (f1 < f2) {
      hi = x2; x2 = x1; f2 = f1; x1 = hi - r * (hi - lo); f1 = f(x1);
    } else {
      lo = x1; x1 = x2; f1 = f2; x2 = lo + r * (hi - lo); f2 = f(x2);
    }
  }
  const double xm = f1 < f2 ? x1 : x2;
  return std::min(f1, f2) < v[best] ? xm : grid[best];
}

}  // namespace mpm::diagnosis
