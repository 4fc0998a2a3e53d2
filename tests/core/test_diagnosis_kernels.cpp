// The diagnosis's whole-record kernels against independent oracles:
// simulate() against DiscreteFilter stepped from rest (bit for bit: the
// kernel claims the same arithmetic in the same order; to rounding where the
// build may fuse multiply-adds), least_squares()
// against a column-pivoting QR of the centred design on the fit samples,
// and its run-indexed path against the per-sample masks.
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "core/diagnosis_signal.hpp"
#include "core/transfer_function.hpp"

namespace {

using mpm::DiscreteFilter;
using mpm::DiscreteTf;
namespace dg = mpm::diagnosis;
using Eigen::Index;
using Eigen::VectorXd;

VectorXd noise(Index n, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  VectorXd x(n);
  for (Index k = 0; k < n; ++k) x(k) = g(rng);
  return x;
}

VectorXd stepped(const DiscreteTf& tf, const VectorXd& x) {
  DiscreteFilter f(tf);
  f.reset(0.0);
  VectorXd y(x.size());
  for (Index k = 0; k < x.size(); ++k) y(k) = f.step(x(k));
  return y;
}

// With FMA instructions in the build (MPM_NATIVE_ARCH: -march=x86-64-v3),
// GCC contracts a * b + c into one rounding wherever it can, and it need not
// do so at the same places in the kernel and in DiscreteFilter: the two then
// agree to rounding, not to the bit. Without FMA the order of operations is
// all there is, and the claim is bit for bit.
#if defined(__FMA__)
constexpr bool kBitForBit = false;
#else
constexpr bool kBitForBit = true;
#endif

TEST(DiagnosisKernels, SimulateIsDiscreteFilterBitForBit) {
  const std::vector<DiscreteTf> tfs{
      {{0.744}, {1.0, -0.9419}, 2},                       // Wood-Berry G11
      {{0.0, 0.3, -0.2}, {1.0, -1.2, 0.5}, 0},            // leading zero, second order
      {{1.0, -0.8}, {1.0}, 0},                            // FIR whitener N^-1
      {{1.0, -0.5, 0.2, -0.1, 0.05, 0.02, -0.01, 0.01, 0.0, 0.003, -0.002}, {1.0}, 0},  // AR(10) whitener
      {{2.0, 1.0}, {2.0, -1.0, 0.3, -0.05}, 7},           // not monic, third order, delay
      {{1.0}, {1.0, -1.0}, 1},                            // integrator
      {{0.5}, {1.0, -0.5}, 3000},                         // delay beyond the record: all zeros
  };
  for (std::size_t t = 0; t < tfs.size(); ++t)
    for (Index n : {Index{0}, Index{1}, Index{5}, Index{2047}, Index{2049}, Index{5000}}) {
      const VectorXd x = noise(n, 7 + static_cast<unsigned>(t));
      const VectorXd a = dg::simulate(tfs[t], x), b = stepped(tfs[t], x);
      ASSERT_EQ(a.size(), b.size());
      if (kBitForBit) {
        // Bit for bit, zeros' signs included.
        EXPECT_EQ(0, n ? std::memcmp(a.data(), b.data(), static_cast<std::size_t>(n) * sizeof(double)) : 0)
            << "filter " << t << ", " << n << " samples";
      } else if (n > 0) {
        EXPECT_LE((a - b).cwiseAbs().maxCoeff(), 1e-12 * (1.0 + b.cwiseAbs().maxCoeff()))
            << "filter " << t << ", " << n << " samples";
      }
    }
}

// Segments as prepare() makes them, with gaps (unusable samples) that split
// the fit and held-out blocks into several runs.
// With `folds`, also the folds of the cross-fitted check (the thirds of the
// blocks, as prepare() makes them).
dg::Segments segments(Index n, bool index, bool folds = false) {
  dg::Segments s;
  s.begin = 30;
  s.fit.assign(static_cast<std::size_t>(n), 0);
  s.hold.assign(static_cast<std::size_t>(n), 0);
  if (folds) s.fold.assign(static_cast<std::size_t>(n), -1);
  const Index block = (n - s.begin) / 10;
  for (Index k = s.begin; k < n; ++k) {
    if (k % 97 == 0 || (k > 1200 && k < 1260)) continue;
    const auto third = static_cast<signed char>(std::min<Index>(9, (k - s.begin) / block) % 3);
    if (folds) s.fold[static_cast<std::size_t>(k)] = third;
    const bool held = third == 2;
    (held ? s.hold : s.fit)[static_cast<std::size_t>(k)] = 1;
    ++(held ? s.hold_n : s.fit_n);
  }
  if (index) s.index();
  return s;
}

TEST(DiagnosisKernels, LeastSquaresMatchesQrOnTheFitSamples) {
  const Index n = 3000;
  const dg::Segments seg = segments(n, true);
  for (int p = 0; p <= 4; ++p) {
    std::vector<VectorXd> x;
    VectorXd y = noise(n, 100);
    for (int i = 0; i < p; ++i) {
      // Offsets well away from zero: the intercept matters.
      x.push_back(noise(n, 200 + static_cast<unsigned>(i)).array() + 3.0 * (i + 1));
      y += (0.5 - 0.3 * i) * x.back();
    }
    y.array() += 2.0;
    const dg::LinearFit f = dg::least_squares(y, x, seg);

    // Oracle: QR of [1, X] on the fit samples; residual variance about the
    // mean; held-out errors about their own mean.
    std::vector<Index> rows;
    for (Index k = 0; k < n; ++k)
      if (seg.fit[static_cast<std::size_t>(k)]) rows.push_back(k);
    const auto m = static_cast<Index>(rows.size());
    Eigen::MatrixXd X(m, p + 1);
    VectorXd t(m);
    for (Index r = 0; r < m; ++r) {
      X(r, 0) = 1.0;
      for (int i = 0; i < p; ++i) X(r, i + 1) = x[static_cast<std::size_t>(i)](rows[static_cast<std::size_t>(r)]);
      t(r) = y(rows[static_cast<std::size_t>(r)]);
    }
    const VectorXd beta = X.colPivHouseholderQr().solve(t);
    const VectorXd e = t - X * beta;
    const double fit_var = e.squaredNorm() / static_cast<double>(m) - std::pow(e.mean(), 2);
    ASSERT_EQ(f.theta.size(), p);
    for (int i = 0; i < p; ++i) EXPECT_NEAR(f.theta(i), beta(i + 1), 1e-11) << "p " << p << " i " << i;
    EXPECT_NEAR(f.fit_var, fit_var, 1e-12 * fit_var);
    VectorXd h = VectorXd::Zero(n);
    double hm = 0.0;
    Index nh = 0;
    for (Index k = 0; k < n; ++k)
      if (seg.hold[static_cast<std::size_t>(k)]) {
        h(k) = y(k) - beta(0);
        for (int i = 0; i < p; ++i) h(k) -= beta(i + 1) * x[static_cast<std::size_t>(i)](k);
        hm += h(k);
        ++nh;
      }
    hm /= static_cast<double>(nh);
    double hv = 0.0;
    for (Index k = 0; k < n; ++k)
      if (seg.hold[static_cast<std::size_t>(k)]) {
        h(k) -= hm;
        hv += h(k) * h(k);
      }
    // Errors about the held-out part's own mean (the intercept drops out).
    EXPECT_NEAR(f.hold_var, hv / static_cast<double>(nh), 1e-10 * f.hold_var);
    EXPECT_LT((f.hold_error - h).cwiseAbs().maxCoeff(), 1e-10);

    // The same fit on masks that were never indexed: the same numbers, bit for bit.
    const dg::LinearFit g = dg::least_squares(y, x, segments(n, false));
    EXPECT_EQ(f.fit_var, g.fit_var);
    EXPECT_EQ(f.hold_var, g.hold_var);
    EXPECT_TRUE(f.theta == g.theta);
    EXPECT_TRUE(f.hold_error == g.hold_error);
  }
}

// The cross-fitted variance against its definition: for each fold, a QR fit
// of [1, X] on the other folds' samples, that fold's errors about their own
// mean, pooled over the folds with their sample counts.
TEST(DiagnosisKernels, CrossFittedVarianceIsEachFoldPredictedByTheOthers) {
  const Index n = 3000;
  const dg::Segments seg = segments(n, true, true);
  ASSERT_EQ(seg.fold_runs.size(), 3u);
  for (int p = 0; p <= 3; ++p) {
    std::vector<VectorXd> x;
    VectorXd y = noise(n, 300);
    for (int i = 0; i < p; ++i) {
      x.push_back(noise(n, 400 + static_cast<unsigned>(i)).array() + 2.0 * (i + 1));
      // A coefficient that differs between the halves of the record: the
      // folds' fits then differ from the fit part's.
      for (Index k = 0; k < n; ++k) y(k) += (k < n / 2 ? 0.4 : 0.9) * x.back()(k);
    }
    const dg::LinearFit f = dg::least_squares(y, x, seg);
    ASSERT_EQ(f.fold_var.size(), 3);
    double pooled = 0.0;
    Index judged = 0;
    for (signed char fold = 0; fold < 3; ++fold) {
      std::vector<Index> train, test;
      for (Index k = 0; k < n; ++k) {
        const signed char at = seg.fold[static_cast<std::size_t>(k)];
        if (at < 0) continue;
        (at == fold ? test : train).push_back(k);
      }
      const auto design = [&](const std::vector<Index>& rows) {
        Eigen::MatrixXd X(static_cast<Index>(rows.size()), p + 1);
        for (std::size_t r = 0; r < rows.size(); ++r) {
          X(static_cast<Index>(r), 0) = 1.0;
          for (int i = 0; i < p; ++i) X(static_cast<Index>(r), i + 1) = x[static_cast<std::size_t>(i)](rows[r]);
        }
        return X;
      };
      const auto target = [&](const std::vector<Index>& rows) {
        VectorXd t(static_cast<Index>(rows.size()));
        for (std::size_t r = 0; r < rows.size(); ++r) t(static_cast<Index>(r)) = y(rows[r]);
        return t;
      };
      const VectorXd beta = design(train).colPivHouseholderQr().solve(target(train));
      const VectorXd e = target(test) - design(test) * beta;
      const double var = e.squaredNorm() / static_cast<double>(e.size()) - std::pow(e.mean(), 2);
      EXPECT_NEAR(f.fold_var(fold), var, 1e-9 * var) << "p " << p << " fold " << int(fold);
      pooled += var * static_cast<double>(e.size());
      judged += e.size();
    }
    EXPECT_NEAR(f.cv_var, pooled / static_cast<double>(judged), 1e-9 * f.cv_var) << "p " << p;
    // The held-out fold is predicted by the fit part: its variance is hold_var.
    EXPECT_EQ(f.fold_var(2), f.hold_var);
    // Without folds there is no cross-fit: cv_var is the held-out variance.
    const dg::LinearFit g = dg::least_squares(y, x, segments(n, true, false));
    EXPECT_EQ(g.cv_var, g.hold_var);
    EXPECT_EQ(g.fold_var.size(), 0);
  }
}

}  // namespace
