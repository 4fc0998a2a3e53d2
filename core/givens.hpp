// OVERVIEW
// The Givens rotations shared by the RLS factors: the square-root one
// (R itself, with the forgetting factor folded in: the tests' SqrtRls) and
// the square-root-free one (ud_rls.cpp, nested_rls.cpp: R = D^1/2 U).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace mpm::givens {

struct Rotation {
  double c = 1.0;
  double s = 0.0;
};

// Rows of the factors are stored padded to a whole number of kLanes values
// (zeros), so the rotations below run over whole vectors: no remainder loop,
// whose set-up would cost as much as the work on rows this short.
constexpr std::size_t kLanes = 4;
constexpr std::size_t padded(std::size_t n) noexcept { return (n + kLanes - 1) / kLanes * kLanes; }

// Four doubles (GCC/Clang vector extension: AVX when compiled for it, else
// two SSE2 halves). Loads and stores are unaligned.
typedef double Lanes __attribute__((vector_size(kLanes * sizeof(double))));
inline Lanes load(const double* p) noexcept {
  Lanes v;
  __builtin_memcpy(&v, p, sizeof v);
  return v;
}
inline void store(double* p, Lanes v) noexcept { __builtin_memcpy(p, &v, sizeof v); }
typedef long long LaneMask __attribute__((vector_size(kLanes * sizeof(long long))));
inline double sum(Lanes v) noexcept {
  double s = 0.0;
  for (std::size_t k = 0; k < kLanes; ++k) s += v[k];
  return s;
}
// The sums of four vectors at once, {sum(a), sum(b), sum(c), sum(d)}: four
// shuffles and three additions instead of four separate reductions.
static_assert(kLanes == 4, "sum4 transposes four vectors of four lanes");
#if defined(__clang__)  // clang spells GCC's __builtin_shuffle with constant indices
#define MPM_SHUFFLE(x, y, i, j, k, l) __builtin_shufflevector(x, y, i, j, k, l)
#else
#define MPM_SHUFFLE(x, y, i, j, k, l) __builtin_shuffle(x, y, LaneMask{i, j, k, l})
#endif
inline Lanes sum4(Lanes a, Lanes b, Lanes c, Lanes d) noexcept {
  const Lanes ab = MPM_SHUFFLE(a, b, 0, 4, 2, 6) + MPM_SHUFFLE(a, b, 1, 5, 3, 7);
  const Lanes cd = MPM_SHUFFLE(c, d, 0, 4, 2, 6) + MPM_SHUFFLE(c, d, 1, 5, 3, 7);
  return MPM_SHUFFLE(ab, cd, 0, 1, 4, 5) + MPM_SHUFFLE(ab, cd, 2, 3, 6, 7);
}
#undef MPM_SHUFFLE
constexpr LaneMask kLaneIndex = {0, 1, 2, 3};

// Rotates the pivot row a, scaled by `scale` first, against row b so that
// b[first] becomes 0; columns [first, end) of both rows are updated and
// a[first] stays >= 0. Returns the rotation (identity when b[first] == 0).
// `end` is a padded width. Columns before `first` in the same block of
// lanes are rotated too: they must be zero in both rows (below the diagonal
// of a triangular factor, and already eliminated from the row being
// absorbed), and stay zero.
inline Rotation rotate(double* __restrict a, double* __restrict b, std::size_t first, std::size_t end,
                       double scale) noexcept {
  const double x = scale * a[first];
  const double y = b[first];
  const std::size_t begin = first / kLanes * kLanes;
  if (y == 0.0) {
    if (scale != 1.0)
      for (std::size_t j = begin; j < end; j += kLanes) store(a + j, load(a + j) * scale);
    return {};
  }
  // The next rotation waits on b[first + 1] only: computed as
  // (x b - y scale a) / r, its products do not wait for the square root and
  // the division, so one product follows them on the critical path instead
  // of three (c, s scale, then the update).
  const std::size_t next = first + 1;
  const bool next_in_block = next - begin < kLanes;
  const double x_next = next_in_block ? x * b[next] : 0.0;
  const double y_next = next_in_block ? y * (scale * a[next]) : 0.0;
  const double inv = 1.0 / std::sqrt(x * x + y * y);  // one division, two products
  const double b_next = (x_next - y_next) * inv;
  const double c = x * inv;
  const double s = y * inv;
  const double cs = c * scale;
  const double ss = s * scale;
  const double pivot = x * c + y * s;
  // The first block: the pivot, the eliminated zero and b[first + 1] set by
  // lane masks, not by scalar stores after a vector store (a later vector
  // load of a block written partly by scalar stores cannot be forwarded from
  // the store buffer and stalls).
  {
    const Lanes a0 = load(a + begin);
    const Lanes b0 = load(b + begin);
    const LaneMask at_first = kLaneIndex == static_cast<long long>(first - begin);
    const LaneMask at_next = kLaneIndex == static_cast<long long>(next - begin);
    const Lanes zero = {0.0, 0.0, 0.0, 0.0};
    const Lanes a1 = at_first ? pivot + zero : cs * a0 + s * b0;
    Lanes b1 = at_first ? zero : c * b0 - ss * a0;
    b1 = at_next ? b_next + zero : b1;
    store(a + begin, a1);
    store(b + begin, b1);
  }
  for (std::size_t j = begin + kLanes; j < end; j += kLanes) {
    const Lanes aj = load(a + j);
    const Lanes bj = load(b + j);
    store(a + j, cs * aj + s * bj);
    store(b + j, c * bj - ss * aj);
  }
  return {c, s};
}

// Gentleman's square-root-free Givens rotation (Gentleman 1973; the update
// of Miller's AS 274), for factors kept as R = D^1/2 U with U unit upper
// triangular: absorbs row b, of weight w, into row `first` of U (u) and its
// diagonal weight d, d forgotten by lambda first, so that b[first] becomes
// 0. w leaves as the weight of what is left of b. Per entry three
// operations (two fused) instead of the Givens rotation's four, and no
// square root: the chain from one row to the next is one division. Same layout
// rules as rotate(): `end` padded, columns before `first` in its block of
// lanes zero in both rows and kept zero.
inline void rotate_sqrt_free(double* __restrict u, double& d, double* __restrict b, double& w, std::size_t first,
                             std::size_t end, double lambda) noexcept {
  const double x = b[first];
  const double forgotten = lambda * d;
  if (x == 0.0 || w == 0.0) {  // nothing of this row enters row `first`
    d = forgotten;
    return;
  }
  // The next row waits on w only: w lambda d and x x are formed beside the
  // chain, which is one multiply-add, the division and one product.
  const double grown = forgotten + w * (x * x);
  const double inv = 1.0 / grown;
  const double cbar = forgotten * inv;
  const double sbar = (w * x) * inv;
  d = grown;
  w = (w * forgotten) * inv;
  const std::size_t begin = first / kLanes * kLanes;
  {
    // The diagonal stays exactly 1 and b[first] exactly 0 (lane masks, as in
    // rotate()): computed, they would be 1 and 0 only up to rounding, and the
    // error would leak below the diagonal.
    const Lanes u0 = load(u + begin);
    const Lanes b0 = load(b + begin);
    const LaneMask at_first = kLaneIndex == static_cast<long long>(first - begin);
    const Lanes zero = {0.0, 0.0, 0.0, 0.0};
    store(b + begin, at_first ? zero : b0 - x * u0);
    store(u + begin, at_first ? 1.0 + zero : cbar * u0 + sbar * b0);
  }
  for (std::size_t j = begin + kLanes; j < end; j += kLanes) {
    const Lanes uj = load(u + j);
    const Lanes bj = load(b + j);
    store(b + j, bj - x * uj);
    store(u + j, cbar * uj + sbar * bj);
  }
}

}  // namespace mpm::givens
