// What bounds the monitor's update from below on this machine, measured in
// the same run as the update itself, so that a missed target is explained by
// numbers rather than words:
//  * memory: the bytes of factor state one update reads and writes back
//    (counted from the storage the core allocates), and the rate at which
//    this core streams a working set of that size (read-modify-write);
//  * latency: each rotation needs the previous one's weight through a
//    division (square-root-free rotations; a square root too in the Givens
//    rotations of the large factors), so an output's update is a chain of
//    dependent steps; the time of one such step, measured.
#pragma once

#include <cstddef>

#include "core/granger_monitor.hpp"

namespace mpm::bench {

// Bytes of factor state one used sample reads (and writes back) in a
// monitor of `inputs` x `outputs` with these settings: for each output the
// shared rows of [1, AR] and their weights, the lower factor of the inputs'
// regressors (in covariance form, with its block covariances, from 4 inputs
// on, as the core does), and the pairwise factors; triangles where the core
// only touches triangles. Mirrors core/nested_rls.cpp, core/ud_rls.cpp and
// core/bierman_rls.cpp.
double state_bytes_per_update(std::size_t inputs, std::size_t outputs, const MonitorSettings& settings);

// Dependent rotations on one output's longest chain: the rows of
// [1, AR] and then the lower factor's rows, one after the other.
std::size_t rotation_chain_length(std::size_t inputs, const MonitorSettings& settings);

struct StreamRate {
  double bytes_per_s = 0.0;   // read + write bytes per second
  double working_set = 0.0;   // bytes
};
// Read-modify-write passes (x = a x + b y) over a working set of about
// `bytes`, one thread, best of a few passes within about `seconds`.
StreamRate measure_stream_rate(double bytes, double seconds);

// Nanoseconds per step of the dependent chain w <- (w f) / (f + w c), the
// critical path of one square-root-free rotation (givens.hpp), best of a
// few runs.
double measure_rotation_step_ns(double seconds);

}  // namespace mpm::bench
