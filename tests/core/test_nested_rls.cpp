// The shared update of a full model and its pairwise models (NestedRls)
// against separate square-root RLS fits of each model on the same rows
// (SqrtRls, itself checked against batch QR in test_rls_factors.cpp).
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "core/nested_rls.hpp"
#include "support/sqrt_rls.hpp"

namespace mpm {
namespace {

constexpr double kDelta = 1e-9;

// Every model of a NestedRls fitted separately: the full model and one
// [A, B_i] model per block.
struct SeparateFits {
  std::size_t a, m, nb;
  SqrtRls full;
  std::vector<SqrtRls> pair;
  SeparateFits(std::size_t a_, std::size_t m_, std::size_t nb_, double lambda)
      : a(a_), m(m_), nb(nb_), full(a_ + m_ * nb_, lambda, kDelta),
        pair(m_, SqrtRls(a_ + nb_, lambda, kDelta)) {}
  void update(const std::vector<double>& x, double y) {
    full.update(x.data(), y);
    std::vector<double> xp(a + nb);
    for (std::size_t i = 0; i < m; ++i) {
      std::copy(x.begin(), x.begin() + static_cast<long>(a), xp.begin());
      std::copy(x.begin() + static_cast<long>(a + i * nb), x.begin() + static_cast<long>(a + (i + 1) * nb),
                xp.begin() + static_cast<long>(a));
      pair[i].update(xp.data(), y);
    }
  }
};

// Rows like the monitor's: intercept, AR lags of y, lags of correlated
// inputs, y depending on the first input and its own past.
class Rows {
 public:
  Rows(std::size_t a, std::size_t m, std::size_t nb) : a_(a), m_(m), nb_(nb), y_hist_(a, 0.0), u_hist_(m, std::vector<double>(nb, 0.0)) {}
  void next(std::vector<double>& x, double& y) {
    x.assign(a_ + m_ * nb_, 0.0);
    x[0] = 1.0;
    for (std::size_t l = 1; l < a_; ++l) x[l] = y_hist_[l - 1];
    for (std::size_t i = 0; i < m_; ++i)
      for (std::size_t l = 0; l < nb_; ++l) x[a_ + i * nb_ + l] = u_hist_[i][l];
    y = 0.4 + 0.6 * y_hist_[0] + 0.5 * u_hist_[0][1] + n_(rng_);
    std::rotate(y_hist_.rbegin(), y_hist_.rbegin() + 1, y_hist_.rend());
    y_hist_[0] = y;
    const double common = n_(rng_);
    for (std::size_t i = 0; i < m_; ++i) {
      auto& h = u_hist_[i];
      std::rotate(h.rbegin(), h.rbegin() + 1, h.rend());
      h[0] = n_(rng_) + 0.6 * common;  // correlated inputs, as in closed loop
    }
  }

 private:
  std::size_t a_, m_, nb_;
  std::vector<double> y_hist_;
  std::vector<std::vector<double>> u_hist_;
  std::mt19937_64 rng_{11};
  std::normal_distribution<double> n_{0.0, 1.0};
};

bool close(double value, double reference, double tol) {
  return std::abs(value - reference) <= tol * std::abs(reference) + 1e-12;
}

void expect_equal_to_separate_fits(std::size_t m, double lambda, int samples, double tol, bool wald_tests) {
  const std::size_t a = 4, nb = 3, p = a + m * nb;
  NestedRls nested(a, m, nb, lambda, kDelta, wald_tests);
  SeparateFits separate(a, m, nb, lambda);
  Rows rows(a, m, nb);
  std::vector<double> x;
  double y = 0.0;
  for (int k = 0; k < samples; ++k) {
    rows.next(x, y);
    nested.update(x.data(), y);
    separate.update(x, y);
  }
  SqrtRls::Matrix scratch(static_cast<Eigen::Index>(p + 1), static_cast<Eigen::Index>(p + 1));
  SqrtRls::Matrix nested_scratch(static_cast<Eigen::Index>(m * nb + 1), static_cast<Eigen::Index>(m * nb + 1));
  const SqrtRls& full = separate.full;
  EXPECT_PRED3(close, nested.rss_full(), full.rss(), tol);
  EXPECT_PRED3(close, nested.rss_prefix_only(), full.rss_prefix(a), tol);
  EXPECT_PRED3(close, nested.rss_head(1), full.rss_prefix(1), tol);
  EXPECT_PRED3(close, nested.rss_head(0), full.rss_prefix(0), tol);
  for (std::size_t i = 0; i < m; ++i) {
    EXPECT_PRED3(close, nested.rss_pair(i), separate.pair[i].rss(), tol) << "block " << i;
    EXPECT_PRED3(close, nested.rss_pair_prefix_only(i), separate.pair[i].rss_prefix(a), tol) << "block " << i;
    EXPECT_PRED3(close, nested.rss_without_block(i, nested_scratch), full.rss_without(a + i * nb, nb, scratch), tol)
        << "block " << i;
    Eigen::VectorXd got(a), want(a + nb);
    nested.solve_pair_prefix(i, got);
    separate.pair[i].solve_prefix(a + nb, want);
    const Eigen::MatrixXd& all = nested.solve_pairs_prefix();  // every pairwise model at once
    for (std::size_t c = 0; c < a; ++c) {
      const auto cc = static_cast<Eigen::Index>(c);
      EXPECT_NEAR(got[cc], want[cc], 1e3 * tol) << "block " << i;
      EXPECT_NEAR(all(cc, static_cast<Eigen::Index>(i)), want[cc], 1e3 * tol) << "block " << i << " (all at once)";
    }
  }
  Eigen::VectorXd got(p), want(p);
  nested.solve_full(got);
  full.solve_prefix(p, want);
  EXPECT_LT((got - want).cwiseAbs().maxCoeff(), 1e3 * tol);
  EXPECT_NEAR(want[static_cast<Eigen::Index>(a + 1)], 0.5, 0.1);  // the planted coefficient is fitted
}

TEST(NestedRls, EqualsSeparateFitsWithoutForgetting) {
  expect_equal_to_separate_fits(1, 1.0, 3000, 1e-9, false);
  expect_equal_to_separate_fits(2, 1.0, 3000, 1e-9, false);  // conditional RSS from the pairwise model
  expect_equal_to_separate_fits(3, 1.0, 3000, 1e-9, false);  // re-triangularisation
  expect_equal_to_separate_fits(5, 1.0, 3000, 1e-9, true);   // Wald identity (covariance form)
}

TEST(NestedRls, EqualsSeparateFitsWithForgetting) {
  // The kept-alive priors are refreshed on other schedules than in the
  // separate fits; with delta = 1e-9 that moves nothing visible.
  expect_equal_to_separate_fits(2, 0.995, 20'000, 1e-7, false);
  expect_equal_to_separate_fits(4, 0.995, 20'000, 1e-7, true);
}

TEST(NestedRls, StaysBoundedWithoutExcitation) {
  // Constant regressors for 10^4 samples with forgetting: the kept-alive
  // priors of the shared rows and of the lower factors must keep every
  // model's coefficients finite.
  const std::size_t a = 3, m = 3, nb = 2, p = a + m * nb;
  NestedRls nested(a, m, nb, 0.98, 1e-6);
  std::vector<double> x(p, 2.0);
  x[0] = 1.0;
  for (int k = 0; k < 10'000; ++k) nested.update(x.data(), 1.0 + 1e-3 * std::sin(k));
  Eigen::VectorXd full(p), pair(a);
  nested.solve_full(full);
  EXPECT_TRUE(full.allFinite());
  EXPECT_LT(full.cwiseAbs().maxCoeff(), 1e6);
  for (std::size_t i = 0; i < m; ++i) {
    nested.solve_pair_prefix(i, pair);
    EXPECT_TRUE(pair.allFinite());
  }
  EXPECT_TRUE(std::isfinite(nested.rss_full()));
  EXPECT_GT(nested.rss_prefix_only(), 0.0);
}

TEST(NestedRls, RejectsEmptyBlocks) {
  EXPECT_THROW(NestedRls(0, 2, 3, 0.99), std::invalid_argument);
  EXPECT_THROW(NestedRls(3, 0, 3, 0.99), std::invalid_argument);
  EXPECT_THROW(NestedRls(3, 2, 0, 0.99), std::invalid_argument);
  EXPECT_THROW(NestedRls(3, 2, 3, 1.5), std::invalid_argument);
}

}  // namespace
}  // namespace mpm
