#include "bench/batch_baseline.hpp"

#include <cmath>
#include <numeric>
#include <stdexcept>

namespace mpm::bench {

SlidingWindowBatch::SlidingWindowBatch(const Workload& w, int ar_order, int input_order, std::size_t window)
    : outputs_(w.outputs),
      inputs_(w.inputs),
      na_(static_cast<std::size_t>(ar_order)),
      nb_(static_cast<std::size_t>(input_order)),
      window_(window),
      first_valid_(std::max(na_, nb_)) {
  if (w.samples <= first_valid_ + window_) throw std::invalid_argument("SlidingWindowBatch: workload shorter than the window");
  valid_rows_ = w.samples - first_valid_;
  const std::size_t p = 1 + na_ + inputs_ * nb_;
  // Regressor rows exactly as the monitor builds them with plain lags.
  for (std::size_t j = 0; j < outputs_; ++j) {
    Eigen::MatrixXd x(static_cast<Eigen::Index>(valid_rows_), static_cast<Eigen::Index>(p + 1));
    for (std::size_t r = 0; r < valid_rows_; ++r) {
      const std::size_t k = first_valid_ + r;
      const auto rr = static_cast<Eigen::Index>(r);
      Eigen::Index c = 0;
      x(rr, c++) = 1.0;
      for (std::size_t l = 1; l <= na_; ++l) x(rr, c++) = w.residual_at(k - l)[j];
      for (std::size_t i = 0; i < inputs_; ++i)
        for (std::size_t l = 1; l <= nb_; ++l) x(rr, c++) = w.u_at(k - l)[i];
      x(rr, c) = w.residual_at(k)[j];
    }
    rows_.push_back(std::move(x));
  }
  // Column sets: full, without each input, AR-only, each pairwise model.
  const auto target = static_cast<Eigen::Index>(p);
  auto range = [](std::size_t from, std::size_t to) {
    std::vector<Eigen::Index> v(to - from);
    std::iota(v.begin(), v.end(), static_cast<Eigen::Index>(from));
    return v;
  };
  std::vector<Eigen::Index> full = range(0, p + 1);
  models_.push_back(full);
  for (std::size_t i = 0; i < inputs_; ++i) {
    std::vector<Eigen::Index> without = range(0, 1 + na_ + i * nb_);
    for (Eigen::Index c : range(1 + na_ + (i + 1) * nb_, p + 1)) without.push_back(c);
    models_.push_back(without);
  }
  std::vector<Eigen::Index> ar_only = range(0, 1 + na_);
  ar_only.push_back(target);
  models_.push_back(ar_only);
  for (std::size_t i = 0; i < inputs_; ++i) {
    std::vector<Eigen::Index> pair = range(0, 1 + na_);
    for (Eigen::Index c : range(1 + na_ + i * nb_, 1 + na_ + (i + 1) * nb_)) pair.push_back(c);
    pair.push_back(target);
    models_.push_back(pair);
  }
  a_.resize(static_cast<Eigen::Index>(window_), static_cast<Eigen::Index>(p + 1));
  beta_.resize(static_cast<Eigen::Index>(p));
}

double SlidingWindowBatch::rss_of(std::size_t output, std::size_t first_row,
                                  const std::vector<Eigen::Index>& columns) {
  const auto cols = static_cast<Eigen::Index>(columns.size());
  const auto rows = static_cast<Eigen::Index>(window_);
  const Eigen::MatrixXd& x = rows_[output];
  for (Eigen::Index c = 0; c < cols; ++c)
    a_.col(c).head(rows) = x.col(columns[static_cast<std::size_t>(c)]).segment(static_cast<Eigen::Index>(first_row), rows);
  // QR of [X y]: the last diagonal element of R is the residual norm.
  qr_.compute(a_.leftCols(cols));
  const double r = qr_.matrixQR()(cols - 1, cols - 1);
  return r * r;
}

double SlidingWindowBatch::update(std::size_t k) {
  const std::size_t first_row = k % (valid_rows_ - window_);
  double checksum = 0.0;
  for (std::size_t j = 0; j < outputs_; ++j) {
    const double rss_full = rss_of(j, first_row, models_[0]);
    for (std::size_t i = 0; i < inputs_; ++i) checksum += std::log(rss_of(j, first_row, models_[1 + i]) / rss_full);
    const double sigma1 = rss_of(j, first_row, models_[1 + inputs_]);
    for (std::size_t i = 0; i < inputs_; ++i) {
      const double rss_pair = rss_of(j, first_row, models_[2 + inputs_ + i]);
      checksum += std::log(sigma1 / rss_pair);
      // gamma needs the pairwise AR coefficients: back-substitute in R.
      const auto q = static_cast<Eigen::Index>(models_[2 + inputs_ + i].size() - 1);
      const auto r = qr_.matrixQR().topLeftCorner(q, q).triangularView<Eigen::Upper>();
      beta_.head(q) = r.solve(qr_.matrixQR().col(q).head(q));
      checksum += beta_.segment(1, static_cast<Eigen::Index>(na_)).squaredNorm();
    }
  }
  return checksum;
}

}  // namespace mpm::bench
