// What the recursive least-squares factors share (UdRls, BiermanRls,
// NestedRls, and the textbook SqrtRls the tests check them against).
//
// Kept-alive prior. With lambda < 1 the information in unexcited directions
// decays and the covariance would blow up. A prior of weight `delta` per
// regressor is kept alive by re-adding, round robin, one scaled unit row
// every K samples (the amortised equivalent of adding (1 - lambda) delta I
// every sample), so the information stays >= ~delta I / 4 at all times and
// the covariance bounded. K <= 64 is chosen so that a direction waits at
// most p K samples, during which its prior decays by no more than a factor
// of 4. With lambda = 1 only the initial prior is there, so the fit equals
// batch least squares with a ridge of delta (negligible at 1e-9).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <optional>

#include <Eigen/Dense>

namespace mpm {

// Row-major: a Givens rotation walks two rows, contiguous in memory.
using RlsMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// The RSS left in the last column of rows x cols of `scratch` (target column
// last, upper triangular but for `count` subdiagonals) once Householder
// reflections have re-triangularised it (overwritten): the RSS of a model
// without an inner block of regressors, from its factor's trailing part.
// Real-time safe.
double retriangularised_rss(RlsMatrix& scratch, std::size_t rows, std::size_t cols, std::size_t count) noexcept;

// The schedule and weight of the kept-alive prior's unit rows over
// `directions` regressors (see above). Real-time safe after construction.
class KeptAlivePrior {
 public:
  static constexpr int kMaxPeriod = 64;
  static constexpr double kDip = 0.25;  // a direction's prior decays by at most this between refreshes

  KeptAlivePrior() = default;
  KeptAlivePrior(std::size_t directions, double lambda, double delta) noexcept
      : directions_(directions), forgets_(lambda < 1.0) {
    if (forgets_) {
      const double k = std::floor(std::log(kDip) / (static_cast<double>(directions) * std::log(lambda)));
      period_ = static_cast<int>(std::clamp(k, 1.0, static_cast<double>(kMaxPeriod)));
    }
    // `directions` rows add (1 - lambda) delta directions K to each
    // direction: the amortised (1 - lambda) delta per sample.
    weight_ = std::sqrt(static_cast<double>(directions) * period_ * (1.0 - lambda) * delta);
  }

  // Called once per sample. When a unit row is due: writes it into
  // row[0, width) (zero but the weight at its index) and returns that index.
  std::optional<std::size_t> due(double* row, std::size_t width) noexcept {
    if (!forgets_ || ++since_ < period_) return std::nullopt;
    since_ = 0;
    const std::size_t index = next_;
    next_ = (next_ + 1) % directions_;
    std::fill(row, row + width, 0.0);
    row[index] = weight_;
    return index;
  }

  void reset() noexcept {
    since_ = 0;
    next_ = 0;
  }

  int period() const noexcept { return period_; }
  // What changes after setup, for checkpoints (in this order).
  template <class V>
  void visit_state(V&& v) {
    v(since_);
    v(next_);
  }

 private:
  std::size_t directions_ = 1;
  bool forgets_ = false;
  int period_ = 1;          // K: samples between unit rows
  double weight_ = 0.0;     // sqrt(directions K (1 - lambda) delta)
  int since_ = 0;
  std::size_t next_ = 0;    // the next direction refreshed
};

}  // namespace mpm
