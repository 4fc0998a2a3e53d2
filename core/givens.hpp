// OVERVIEW
// The Givens rotation shared by the square-root RLS factors (sqrt_rls.cpp,
// nested_rls.cpp), with the forgetting factor folded in, and the period of
// the kept-alive prior row both use.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace mpm::givens {

struct Rotation {
  double c = 1.0;
  double s = 0.0;
};

// Rotates the pivot row a, scaled by `scale` first, against row b so that
// b[first] becomes 0; columns [first, end) of both rows are updated and
// a[first] stays >= 0. Returns the rotation (identity when b[first] == 0).
inline Rotation rotate(double* __restrict a, double* __restrict b, std::size_t first, std::size_t end,
                       double scale) noexcept {
  const double x = scale * a[first];
  const double y = b[first];
  if (y == 0.0) {
    if (scale != 1.0)
      for (std::size_t j = first; j < end; ++j) a[j] *= scale;
    return {};
  }
  const double inv = 1.0 / std::sqrt(x * x + y * y);  // one division, two products
  const double c = x * inv;
  const double s = y * inv;
  const double cs = c * scale;
  const double ss = s * scale;
  a[first] = x * c + y * s;
  b[first] = 0.0;
  for (std::size_t j = first + 1; j < end; ++j) {
    const double aj = a[j];
    const double bj = b[j];
    a[j] = cs * aj + s * bj;
    b[j] = c * bj - ss * aj;
  }
  return {c, s};
}

// The same rotation on the inverse's rows: [a / scale; b] (columns [0, end)).
inline void rotate_inverse(double* __restrict a, double* __restrict b, std::size_t end, Rotation rot,
                           double inv_scale) noexcept {
  const double ci = rot.c * inv_scale;
  const double si = rot.s * inv_scale;
  for (std::size_t j = 0; j < end; ++j) {
    const double aj = a[j];
    const double bj = b[j];
    a[j] = ci * aj + rot.s * bj;
    b[j] = rot.c * bj - si * aj;
  }
}

// Kept-alive prior (see sqrt_rls.hpp): one unit row every K samples, round
// robin over `directions` regressors. K is as large as kMaxPriorPeriod allows
// (fewer rotation chains), but a direction's prior may decay by at most
// kPriorDip between two refreshes (directions * K samples apart).
constexpr int kMaxPriorPeriod = 64;
constexpr double kPriorDip = 0.25;

inline int prior_period(std::size_t directions, double lambda) noexcept {
  if (lambda >= 1.0) return 1;
  const double k = std::floor(std::log(kPriorDip) / (static_cast<double>(directions) * std::log(lambda)));
  return static_cast<int>(std::clamp(k, 1.0, static_cast<double>(kMaxPriorPeriod)));
}

// Weight of that row: `directions` of them add (1 - lambda) * delta *
// directions * K to each direction, the amortised (1 - lambda) delta per sample.
inline double prior_weight(std::size_t directions, int period, double lambda, double delta) noexcept {
  return std::sqrt(static_cast<double>(directions) * period * (1.0 - lambda) * delta);
}

}  // namespace mpm::givens
