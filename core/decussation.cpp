// Decussation baseline (CAID + MQI); the method is described in the OVERVIEW
// of decussation.hpp. Batch code: clarity over speed, allocation allowed.
#include "core/decussation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "core/noise_filter.hpp"

namespace mpm {
namespace {

using Eigen::Index;
using Eigen::MatrixXd;
using Eigen::VectorXd;

// Fraction of the N filter's impulse-response energy allowed to be missing
// when it starts from rest inside a run of data.
constexpr double kSettledTailEnergy = 1e-4;
constexpr int kMaxSettlingLength = 20000;
constexpr Index kMinEvaluationSamples = 10;

[[noreturn]] void fail(const std::string& what) {
  throw std::invalid_argument("decussation: " + what);
}

// A maximal run of rows with every u and d~ value finite.
struct Run {
  Index begin = 0;
  Index length = 0;
};

std::vector<Run> finite_runs(const MatrixXd& u, const MatrixXd& residual) {
  std::vector<Run> runs;
  Run current;
  for (Index k = 0; k < u.rows(); ++k) {
    const bool finite = u.row(k).allFinite() && residual.row(k).allFinite();
    if (finite) {
      if (current.length == 0) current.begin = k;
      ++current.length;
    } else if (current.length > 0) {
      runs.push_back(current);
      current = Run{};
    }
  }
  if (current.length > 0) runs.push_back(current);
  return runs;
}

// N scaled to num[0] = 1 after checking it is usable: the projection's
// innovation already carries num[0], and only a stable, minimum-phase N with
// no delay has the white noise a as the innovation of N a.
DiscreteTf monic_noise_model(DiscreteTf n, std::size_t output) {
  const std::string who = "noise model of output " + std::to_string(output) + ": ";
  try {
    n.normalise();
    static_cast<void>(inverse(n));  // throws unless delay 0, num[0] != 0, minimum phase
  } catch (const std::invalid_argument& e) {
    fail(who + e.what());
  }
  if (!n.is_stable()) fail(who + "unstable (a pole on or outside the unit circle)");
  const double n0 = n.num.front();
  for (double& c : n.num) c /= n0;
  return n;
}

// Samples after which a filter started from rest has caught up: the tail of
// its impulse response beyond that point holds < kSettledTailEnergy of the
// energy.
int settling_length(const DiscreteTf& n) {
  DiscreteFilter filter(n);
  const auto length = static_cast<std::size_t>(kMaxSettlingLength);
  std::vector<double> energy_before(length + 1, 0.0);
  for (std::size_t t = 0; t < length; ++t) {
    const double h = filter.step(t == 0 ? 1.0 : 0.0);
    energy_before[t + 1] = energy_before[t] + h * h;
  }
  const double total = energy_before.back();
  for (std::size_t t = 0; t <= length; ++t) {
    if (total - energy_before[t] <= kSettledTailEnergy * total) return static_cast<int>(t);
  }
  return kMaxSettlingLength;
}

// Innovations a_bar (full length, NaN where undefined) from one
// least-squares projection of d~(k) on [1, d~(k-1..k-p), u(k-1..k-p)].
struct Projection {
  MatrixXd innovations;
  Index rows = 0;
};

Projection project_on_past(const MatrixXd& u, const MatrixXd& residual,
                           const std::vector<Run>& runs, int p) {
  const Index m = u.cols();
  const Index n = residual.cols();
  const Index cols = 1 + p * (n + m);
  Index rows = 0;
  for (const Run& r : runs) rows += std::max<Index>(0, r.length - p);
  if (rows < 2 * cols) {
    fail("too few finite contiguous samples: the projection has " + std::to_string(rows) +
         " rows for " + std::to_string(cols) + " regressors (needs at least twice as many)");
  }
  MatrixXd z(rows, cols);
  MatrixXd target(rows, n);
  std::vector<Index> sample_of_row;
  sample_of_row.reserve(static_cast<std::size_t>(rows));
  Index row = 0;
  for (const Run& r : runs) {
    for (Index k = r.begin + p; k < r.begin + r.length; ++k, ++row) {
      z(row, 0) = 1.0;
      for (int lag = 1; lag <= p; ++lag) {
        const Index col = 1 + (lag - 1) * (n + m);
        z.block(row, col, 1, n) = residual.row(k - lag);
        z.block(row, col + n, 1, m) = u.row(k - lag);
      }
      target.row(row) = residual.row(k);
      sample_of_row.push_back(k);
    }
  }
  const Eigen::ColPivHouseholderQR<MatrixXd> qr(z);
  const MatrixXd fitted = z * qr.solve(target);
  // Unbiased innovation variance: the fit absorbed `rank` degrees of freedom.
  const double dof_scale =
      std::sqrt(static_cast<double>(rows) / static_cast<double>(rows - qr.rank()));
  Projection out;
  out.rows = rows;
  out.innovations = MatrixXd::Constant(u.rows(), n, std::numeric_limits<double>::quiet_NaN());
  for (Index r = 0; r < rows; ++r) {
    out.innovations.row(sample_of_row[static_cast<std::size_t>(r)]) =
        dof_scale * (target.row(r) - fitted.row(r));
  }
  return out;
}

// Filters each column of x through its own filter, run by run, from rest at
// offset `start` into each run; NaN elsewhere.
MatrixXd filter_runs(const MatrixXd& x, const std::vector<Run>& runs,
                     const std::vector<DiscreteTf>& filters, int start) {
  MatrixXd out = MatrixXd::Constant(x.rows(), x.cols(), std::numeric_limits<double>::quiet_NaN());
  for (Index j = 0; j < x.cols(); ++j) {
    DiscreteFilter filter(filters[static_cast<std::size_t>(j)]);
    for (const Run& r : runs) {
      filter.reset(0.0);
      for (Index k = r.begin + start; k < r.begin + r.length; ++k) out(k, j) = filter.step(x(k, j));
    }
  }
  return out;
}

// Samples at least `skip` into their run: where the filters have settled and
// u has caid_max_lag samples of history inside the same run.
std::vector<Index> evaluation_samples(const std::vector<Run>& runs, Index skip) {
  std::vector<Index> samples;
  for (const Run& r : runs) {
    for (Index k = r.begin + skip; k < r.begin + r.length; ++k) samples.push_back(k);
  }
  return samples;
}

VectorXd gather(const MatrixXd& x, Index col, const std::vector<Index>& samples, Index lag) {
  VectorXd v(static_cast<Index>(samples.size()));
  for (std::size_t s = 0; s < samples.size(); ++s) {
    v(static_cast<Index>(s)) = x(samples[s] - lag, col);
  }
  return v;
}

double variance(const VectorXd& x) {
  const VectorXd centred = x.array() - x.mean();
  return centred.squaredNorm() / static_cast<double>(x.size());
}

// Pearson correlation; 0 when either signal is constant (no evidence).
double correlation(const VectorXd& x, const VectorXd& y) {
  const VectorXd xc = x.array() - x.mean();
  const VectorXd yc = y.array() - y.mean();
  const double denom = std::sqrt(xc.squaredNorm() * yc.squaredNorm());
  return denom > 0.0 ? xc.dot(yc) / denom : 0.0;
}

// Signed correlation of largest magnitude over lags 0..max_lag, and its lag.
std::pair<double, int> peak_cross_correlation(const MatrixXd& u, Index input,
                                              const VectorXd& ds,
                                              const std::vector<Index>& samples,
                                              int max_lag) {
  std::pair<double, int> best{0.0, 0};
  for (int lag = 0; lag <= max_lag; ++lag) {
    const double r = correlation(gather(u, input, samples, lag), ds);
    if (std::abs(r) > std::abs(best.first)) best = {r, lag};
  }
  return best;
}

// The batch signals MQI and CAID are read from, on the evaluation samples.
struct Signals {
  const MatrixXd* u = nullptr;
  const MatrixXd* residual = nullptr;     // d~
  MatrixXd innovations;                    // a_bar
  MatrixXd whitened;                       // a~ = N^-1 d~
  MatrixXd disturbance;                    // d_bar = N a_bar
  std::vector<Index> samples;
};

// MQI, CAID and the located channels of output j, written into `result`.
void score_output(const Signals& sig, Index j, const DecussationSettings& settings,
                  DecussationResult& result) {
  const double innovation_var = variance(gather(sig.innovations, j, sig.samples, 0));
  const double whitened_var = variance(gather(sig.whitened, j, sig.samples, 0));
  result.innovation_variance(j) = innovation_var;
  // A constant residual gives no evidence either way: MQI is NaN, not flagged.
  result.mqi(j) = whitened_var > 0.0 ? innovation_var / whitened_var
                                     : std::numeric_limits<double>::quiet_NaN();
  const bool flagged = result.mqi(j) < settings.mqi_threshold;
  result.output_flagged[static_cast<std::size_t>(j)] = flagged;
  result.mismatch = result.mismatch || flagged;

  const VectorXd ds =
      gather(*sig.residual, j, sig.samples, 0) - gather(sig.disturbance, j, sig.samples, 0);
  for (Index i = 0; i < sig.u->cols(); ++i) {
    const auto [r, lag] =
        peak_cross_correlation(*sig.u, i, ds, sig.samples, settings.caid_max_lag);
    result.caid(j, i) = r;
    result.caid_lag(j, i) = lag;
    if (flagged && std::abs(r) >= settings.caid_threshold) {
      result.located.emplace_back(static_cast<std::size_t>(j), static_cast<std::size_t>(i));
    }
  }
}

void check_sizes(const MatrixXd& u, const MatrixXd& residual,
                 const std::vector<DiscreteTf>& noise_models) {
  if (u.cols() == 0) fail("u has no input columns");
  if (residual.cols() == 0) fail("residual has no output columns");
  if (u.rows() != residual.rows()) {
    fail("u has " + std::to_string(u.rows()) + " samples but residual has " +
         std::to_string(residual.rows()));
  }
  if (noise_models.size() != static_cast<std::size_t>(residual.cols())) {
    fail(std::to_string(noise_models.size()) + " noise models for " +
         std::to_string(residual.cols()) + " residual columns (need one per output)");
  }
}

}  // namespace

void DecussationSettings::validate() const {
  if (past_order < 1) fail("past_order must be >= 1, got " + std::to_string(past_order));
  if (caid_max_lag < 0) fail("caid_max_lag must be >= 0, got " + std::to_string(caid_max_lag));
  if (!(mqi_threshold > 0.0 && mqi_threshold <= 1.0)) {
    fail("mqi_threshold must be in (0, 1], got " + std::to_string(mqi_threshold));
  }
  if (!(caid_threshold > 0.0 && caid_threshold < 1.0)) {
    fail("caid_threshold must be in (0, 1), got " + std::to_string(caid_threshold));
  }
}

DecussationResult decussation(const MatrixXd& u, const MatrixXd& residual,
                              const std::vector<DiscreteTf>& noise_models,
                              const DecussationSettings& settings) {
  settings.validate();
  check_sizes(u, residual, noise_models);
  const Index n = residual.cols();
  const Index m = u.cols();
  const int p = settings.past_order;

  std::vector<DiscreteTf> monic;
  std::vector<DiscreteTf> whitening;
  int settle = 0;
  for (std::size_t j = 0; j < noise_models.size(); ++j) {
    monic.push_back(monic_noise_model(noise_models[j], j));
    whitening.push_back(inverse(monic.back()));
    settle = std::max({settle, p + settling_length(monic.back()),
                       settling_length(whitening.back())});
  }

  const std::vector<Run> runs = finite_runs(u, residual);
  Projection projection = project_on_past(u, residual, runs, p);
  Signals sig;
  sig.u = &u;
  sig.residual = &residual;
  sig.disturbance = filter_runs(projection.innovations, runs, monic, p);
  sig.innovations = std::move(projection.innovations);
  sig.whitened = filter_runs(residual, runs, whitening, 0);
  const Index skip = std::max<Index>(settle, settings.caid_max_lag);
  sig.samples = evaluation_samples(runs, skip);
  if (static_cast<Index>(sig.samples.size()) < kMinEvaluationSamples) {
    fail("too few settled samples for MQI/CAID: " + std::to_string(sig.samples.size()) +
         " (each run of finite data loses its first " + std::to_string(skip) + ")");
  }

  DecussationResult result;
  result.mqi.resize(n);
  result.innovation_variance.resize(n);
  result.caid.resize(n, m);
  result.caid_lag.resize(n, m);
  result.output_flagged.assign(static_cast<std::size_t>(n), false);
  result.regression_rows = static_cast<std::size_t>(projection.rows);
  result.samples_used = sig.samples.size();
  for (Index j = 0; j < n; ++j) score_output(sig, j, settings, result);
  return result;
}

}  // namespace mpm
