#include "core/rls_common.hpp"

namespace mpm {

double retriangularised_rss(RlsMatrix& scratch, std::size_t rows, std::size_t cols, std::size_t count) noexcept {
  constexpr std::size_t kChunk = 64;
  for (std::size_t c = 0; c + 1 < cols; ++c) {
    const std::size_t last_row = std::min(rows - 1, c + count);
    double sigma = 0.0;  // squares below the diagonal
    for (std::size_t r = c + 1; r <= last_row; ++r) {
      const double v = scratch(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c));
      sigma += v * v;
    }
    if (sigma == 0.0) continue;
    double* pivot = scratch.row(static_cast<Eigen::Index>(c)).data();
    const double alpha = pivot[c];
    const double norm = std::sqrt(alpha * alpha + sigma);
    const double v0 = alpha >= 0.0 ? alpha + norm : alpha - norm;  // v = [v0, x below]
    const double tau = 2.0 / (v0 * v0 + sigma);
    // In chunks of columns: proj = tau v^T A[c:, chunk], then A -= v proj.
    for (std::size_t j0 = c + 1; j0 < cols; j0 += kChunk) {
      const std::size_t j1 = std::min(cols, j0 + kChunk);
      double proj[kChunk];
      for (std::size_t j = j0; j < j1; ++j) proj[j - j0] = v0 * pivot[j];
      for (std::size_t r = c + 1; r <= last_row; ++r) {
        const double* row = scratch.row(static_cast<Eigen::Index>(r)).data();
        const double vr = row[c];
        for (std::size_t j = j0; j < j1; ++j) proj[j - j0] += vr * row[j];
      }
      for (std::size_t j = j0; j < j1; ++j) proj[j - j0] *= tau;
      for (std::size_t j = j0; j < j1; ++j) pivot[j] -= v0 * proj[j - j0];
      for (std::size_t r = c + 1; r <= last_row; ++r) {
        double* row = scratch.row(static_cast<Eigen::Index>(r)).data();
        const double vr = row[c];
        for (std::size_t j = j0; j < j1; ++j) row[j] -= vr * proj[j - j0];
      }
    }
    for (std::size_t r = c + 1; r <= last_row; ++r) scratch(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(c)) = 0.0;
    pivot[c] = alpha >= 0.0 ? -norm : norm;
  }
  double s = 0.0;
  for (std::size_t r = cols - 1; r < rows; ++r) {
    const double v = scratch(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(cols - 1));
    s += v * v;
  }
  return s;
}

}  // namespace mpm
