// Independent batch least-squares reference for the recursive factors
// (SqrtRls, UdRls): Householder QR over the stacked data, and the
// correlated ARX-like data both are tested on.
#pragma once

#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Dense>

namespace mpm::test {

constexpr double kDelta = 1e-9;

// Batch reference: accumulates the R factor of [sqrt(w) X, sqrt(w) y] with
// Householder QR over blocks (TSQR), plus the prior rows sqrt(delta) I.
class BatchQr {
 public:
  explicit BatchQr(int p) : p_(p), r_(Eigen::MatrixXd::Zero(p + 1, p + 1)) {
    for (int i = 0; i < p; ++i) r_(i, i) = std::sqrt(kDelta);
  }
  void add_block(const Eigen::MatrixXd& rows) {  // rows: n x (p+1)
    Eigen::MatrixXd stacked(r_.rows() + rows.rows(), p_ + 1);
    stacked << r_, rows;
    Eigen::HouseholderQR<Eigen::MatrixXd> qr(stacked);
    r_ = qr.matrixQR().topRows(p_ + 1).triangularView<Eigen::Upper>();
  }
  // RSS of the LS fit on the regressor columns `keep` (indices < p).
  double rss(const std::vector<int>& keep) const {
    if (keep.empty()) return r_.col(p_).squaredNorm();
    Eigen::MatrixXd x(r_.rows(), static_cast<Eigen::Index>(keep.size()));
    for (std::size_t c = 0; c < keep.size(); ++c) x.col(static_cast<Eigen::Index>(c)) = r_.col(keep[c]);
    const Eigen::VectorXd y = r_.col(p_);
    const Eigen::VectorXd beta = x.colPivHouseholderQr().solve(y);
    return (y - x * beta).squaredNorm();
  }
  Eigen::VectorXd beta() const {
    return r_.topLeftCorner(p_, p_).triangularView<Eigen::Upper>().solve(r_.col(p_).head(p_));
  }

 private:
  int p_;
  Eigen::MatrixXd r_;
};

// ARX-like data: regressors correlated with each other and with y.
struct DataGen {
  std::mt19937_64 rng{42};
  std::normal_distribution<double> n{0.0, 1.0};
  Eigen::VectorXd state;
  explicit DataGen(int p) : state(Eigen::VectorXd::Zero(p)) {}
  void next(Eigen::Ref<Eigen::VectorXd> x, double& y) {
    for (Eigen::Index i = 0; i < state.size(); ++i) state[i] = 0.7 * state[i] + n(rng) + (i > 0 ? 0.3 * state[i - 1] : 0.0);
    x = state;
    x[0] = 1.0;  // intercept
    y = 0.5 + 0.8 * x[1] - 0.3 * x[x.size() - 1] + n(rng);
  }
};

// Feeds `rows.rows()` samples of `gen` to `rls` and keeps them as the rows
// [x' y] of `rows`, so that a batch fit sees exactly the data the recursion saw.
template <typename Rls>
void feed(Rls& rls, DataGen& gen, Eigen::MatrixXd& rows) {
  const Eigen::Index p = rows.cols() - 1;
  Eigen::VectorXd x(p);
  double y = 0;
  for (Eigen::Index k = 0; k < rows.rows(); ++k) {
    gen.next(x, y);
    rls.update(x.data(), y);
    rows.row(k).head(p) = x.transpose();
    rows(k, p) = y;
  }
}

inline std::vector<int> range_except(int p, int first, int count) {
  std::vector<int> v;
  for (int i = 0; i < p; ++i)
    if (i < first || i >= first + count) v.push_back(i);
  return v;
}

}  // namespace mpm::test
