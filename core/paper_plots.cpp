#include "core/paper_plots.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace mpm {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The regressor row of sample k: d~ lags 1..A, then per input its lags
// 1..B, then the target d~(k).
void fill_row(const Eigen::VectorXd& d, const Eigen::MatrixXd& u, Eigen::Index k, int a, int b, double* row) {
  std::size_t c = 0;
  for (int l = 1; l <= a; ++l) row[c++] = d(k - l);
  for (Eigen::Index i = 0; i < u.cols(); ++i)
    for (int l = 1; l <= b; ++l) row[c++] = u(k - l, i);
  row[c] = d(k);
}

}  // namespace

OrderSweep order_sweep(const Eigen::VectorXd& d, const Eigen::MatrixXd& u, int max_ar, int max_input) {
  if (max_ar < 1 || max_input < 0) throw std::invalid_argument("order_sweep: max_ar >= 1 and max_input >= 0");
  if (u.rows() != d.size()) throw std::invalid_argument("order_sweep: d and u have different lengths");
  const Eigen::Index m = u.cols(), p = max_ar + m * max_input + 1, target = p - 1;
  const Eigen::Index first = std::max(max_ar, max_input);

  // Rows whose every lag and target is finite: the same rows for every
  // model, so that the curves compare like with like.
  std::vector<Eigen::Index> rows;
  Eigen::Index bad_d = -1, bad_u = -1;  // last index with a missing value
  for (Eigen::Index k = 0; k < d.size(); ++k) {
    if (!std::isfinite(d(k))) bad_d = k;
    if (k >= 1 && !u.row(k - 1).allFinite()) bad_u = k - 1;
    if (k >= first && bad_d < k - max_ar && bad_u < k - max_input) rows.push_back(k);
  }
  OrderSweep out;
  out.max_ar = max_ar;
  out.max_input = max_input;
  out.used = rows.size();
  out.variance.assign(static_cast<std::size_t>(m),
                      std::vector<std::vector<double>>(static_cast<std::size_t>(max_input) + 1,
                                                       std::vector<double>(static_cast<std::size_t>(max_ar), kNaN)));
  out.ar.assign(static_cast<std::size_t>(m), std::vector<double>(static_cast<std::size_t>(max_ar), kNaN));

  // Centred Gram matrix (the intercept of every model, taken out once:
  // with the same rows, regressing centred columns is the fit with a
  // constant), accumulated row by row.
  Eigen::VectorXd mean = Eigen::VectorXd::Zero(p), row(p);
  for (Eigen::Index k : rows) {
    fill_row(d, u, k, max_ar, max_input, row.data());
    mean += row;
  }
  if (rows.empty()) return out;
  mean /= static_cast<double>(rows.size());
  Eigen::MatrixXd gram = Eigen::MatrixXd::Zero(p, p);
  for (Eigen::Index k : rows) {
    fill_row(d, u, k, max_ar, max_input, row.data());
    row -= mean;
    gram.selfadjointView<Eigen::Lower>().rankUpdate(row);
  }
  gram = gram.selfadjointView<Eigen::Lower>();
  const double n = static_cast<double>(rows.size());

  const auto n_inputs = static_cast<std::size_t>(m), n_ar = static_cast<std::size_t>(max_ar),
             n_lags = static_cast<std::size_t>(max_input);
  for (std::size_t i = 0; i < n_inputs; ++i) {
    for (std::size_t nb = 0; nb <= n_lags; ++nb) {
      for (std::size_t na = 1; na <= n_ar; ++na) {
        std::vector<Eigen::Index> cols;  // d~ lags 1..na, then u_i lags 1..nb
        for (std::size_t l = 0; l < na; ++l) cols.push_back(static_cast<Eigen::Index>(l));
        for (std::size_t l = 0; l < nb; ++l) cols.push_back(static_cast<Eigen::Index>(n_ar + i * n_lags + l));
        const auto q = static_cast<Eigen::Index>(cols.size());
        if (n <= static_cast<double>(q + 1)) continue;
        Eigen::MatrixXd gxx(q, q);
        Eigen::VectorXd gxy(q);
        for (std::size_t r = 0; r < cols.size(); ++r) {
          const auto er = static_cast<Eigen::Index>(r);
          gxy(er) = gram(cols[r], target);
          for (std::size_t c = 0; c < cols.size(); ++c) gxx(er, static_cast<Eigen::Index>(c)) = gram(cols[r], cols[c]);
        }
        const Eigen::LDLT<Eigen::MatrixXd> ldlt(gxx);
        if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0.0)) continue;
        const Eigen::VectorXd beta = ldlt.solve(gxy);
        out.variance[i][nb][na - 1] = std::max(0.0, gram(target, target) - beta.dot(gxy)) / n;
        if (na == n_ar && nb == n_lags)
          for (std::size_t l = 0; l < n_ar; ++l) out.ar[i][l] = beta(static_cast<Eigen::Index>(l));
      }
    }
  }
  return out;
}

double detector_evidence(const SequentialDetector& detector, std::size_t j) noexcept {
  double best = 0.0;
  for (std::size_t k = 0; k < detector.windows(); ++k) {
    const double h = detector.threshold_now(j, k), t = detector.last(j, k);
    if (h > 0.0 && std::isfinite(t)) best = std::max(best, t / h);
  }
  return best;
}

}  // namespace mpm
