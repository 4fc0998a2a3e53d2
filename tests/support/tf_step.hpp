// The unit step response of a discrete channel, samples 0 .. n-1 (the step
// at k = 0), as its own filter produces it: shared by the transfer-function
// and state-space tests.
#pragma once

#include <vector>

#include "core/transfer_function.hpp"

namespace mpm::test {

inline std::vector<double> tf_step(const DiscreteTf& tf, int n) {
  DiscreteFilter f(tf);
  std::vector<double> y;
  for (int k = 0; k < n; ++k) y.push_back(f.step(1.0));
  return y;
}

}  // namespace mpm::test
