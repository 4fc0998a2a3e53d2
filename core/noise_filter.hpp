// The disturbance model N of one output and its inverse N^-1, which whitens
// the residual: a~ = N^-1 d~ (paper, Sec. 3.3).
#pragma once

#include <vector>

#include "core/transfer_function.hpp"

namespace mpm {

// Coefficients g of 1 - N^-1(q) = g_1 q^-1 + g_2 q^-2 + ... truncated to
// `order` terms: these are what the AR part of a regression of d~ on its own
// lags converges to when the residual is N a (paper eq. 88). Throws
// std::invalid_argument if N is not invertible (num[0] == 0, delay != 0) or
// N^-1 is unstable (N non-minimum-phase).
std::vector<double> inverse_noise_ar_coefficients(const DiscreteTf& n, int order);

// Variance of d = N a for white a of the given variance (sum of the squared
// impulse response of N, to 1e-12 relative). +inf if N is not stable.
double noise_output_variance(const DiscreteTf& n, double a_variance);

// N^-1 = den/num as a filter. Same preconditions as above.
DiscreteTf inverse(const DiscreteTf& n);

}  // namespace mpm
