// Two monitors' status messages compared: the counters and flags must be
// equal; the statistics are compared by their largest relative difference,
// which the caller bounds (0 for a resume in this process, 1e-12 across a
// process restart). Shared by the checkpoint unit and loopback tests.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "transport/messages.hpp"

namespace mpm::test {

// Largest relative difference of two numbers (0 when both are NaN or equal).
inline double rel(double a, double b) {
  if ((std::isnan(a) && std::isnan(b)) || a == b) return 0.0;
  return std::abs(a - b) / std::max(std::abs(a), std::abs(b));
}

// Fails on any differing counter, flag or shape; returns the largest relative
// difference of the statistics (1 when the shapes differ).
inline double compare_status(const msg::Status& a, const msg::Status& b) {
  EXPECT_EQ(a.samples_seen, b.samples_seen);
  EXPECT_EQ(a.samples_used, b.samples_used);
  EXPECT_EQ(a.alarms_raised, b.alarms_raised);
  EXPECT_EQ(a.ready, b.ready);
  double worst = rel(a.effective_samples, b.effective_samples);
  if (a.channels.size() != b.channels.size() || a.loops.size() != b.loops.size()) {
    ADD_FAILURE() << "different shapes";
    return 1.0;
  }
  for (std::size_t c = 0; c < a.channels.size(); ++c) {
    const auto& x = a.channels[c];
    const auto& y = b.channels[c];
    EXPECT_EQ(x.alarm, y.alarm) << c;
    for (const auto& [p, q] : {std::pair{x.f_pairwise, y.f_pairwise}, {x.f_conditional, y.f_conditional},
                               {x.lr, y.lr}, {x.gamma, y.gamma}}) {
      worst = std::max(worst, rel(p, q));
    }
  }
  for (std::size_t j = 0; j < a.loops.size(); ++j) {
    const auto& x = a.loops[j];
    const auto& y = b.loops[j];
    EXPECT_EQ(x.alarm, y.alarm) << j;
    for (const auto& [p, q] :
         {std::pair{x.residual_variance, y.residual_variance}, {x.sigma1, y.sigma1}, {x.sigma_full, y.sigma_full}}) {
      worst = std::max(worst, rel(p, q));
    }
  }
  return worst;
}

}  // namespace mpm::test
