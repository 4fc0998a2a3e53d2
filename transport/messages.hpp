// The three messages of the monitor as plain C++ data, independent of the
// transport that carries them (messages/mpm.lcm and messages/mpm.idl hold the
// wire definitions; README.md documents the fields).
//
// The daemon reuses one Sample object per queue slot: assigning into vectors
// that already have the capacity does not allocate, so the receive path is
// allocation free once the first samples have sized them.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace mpm::msg {

struct Sample {
  std::string controller_id;
  std::int64_t session_id = 0;  // random per publisher start; 0 = not used
  std::int64_t seq = 0;         // 1, 2, 3, ... per session
  std::int64_t utime = 0;       // microseconds since the Unix epoch
  std::vector<double> u;        // plant inputs, plant file order
  std::vector<double> y;        // plant outputs, plant file order
  std::vector<double> sim_y;    // empty, or the controller's model prediction of y
  std::vector<std::string> extra_names;
  std::vector<double> extra_values;
};

struct Alarm {
  std::string controller_id;
  std::int64_t utime = 0;
  std::int64_t sample_sequence = 0;
  std::string output;
  std::string input;
  std::int32_t output_index = 0;
  std::int32_t input_index = 0;
  bool raised = false;
  double f = 0.0;
  double p_value = 1.0;
  double gamma = 0.0;     // NaN when unknown
  std::string physics;    // "" when unknown
  std::string text;
};

// The offline diagnosis of a raised output (transport/README.md).
struct Diagnosis {
  std::string controller_id;
  std::int64_t utime = 0;
  std::int64_t sample_sequence = 0;
  std::string output;
  std::string input;
  std::int32_t output_index = 0;
  std::int32_t input_index = 0;
  std::int32_t window = 0;
  bool found = false;
  std::string physics;   // "" when nothing was found
  std::string channels;
  std::vector<std::string> parameter_names;
  std::vector<double> parameter_values;
  double holdout_improvement = 0.0;
  std::string text;
};

struct ChannelStatus {
  std::string output;
  std::string input;
  double f_pairwise = 0.0;
  double f_conditional = 0.0;
  double lr = 0.0;
  double p_value = 1.0;
  double gamma = 0.0;
  bool alarm = false;
};

struct LoopStatus {
  std::string output;
  double residual_variance = 0.0;
  double sigma1 = 0.0;
  double sigma_full = 0.0;
  bool alarm = false;
  bool diverging = false;
};

struct Status {
  std::string controller_id;
  std::int64_t utime = 0;
  std::int64_t uptime_ms = 0;
  bool ready = false;
  double effective_samples = 0.0;
  double raise_threshold = 0.0;
  double clear_threshold = 0.0;
  std::int64_t samples_seen = 0;
  std::int64_t samples_used = 0;
  std::int64_t dropped = 0;
  std::int64_t gaps = 0;
  std::int64_t missing = 0;
  std::int64_t duplicates = 0;
  std::int64_t out_of_order = 0;
  std::int64_t restarts = 0;
  std::int64_t malformed = 0;
  std::int64_t nan_samples = 0;
  std::int64_t alarms_raised = 0;
  std::vector<ChannelStatus> channels;
  std::vector<LoopStatus> loops;
};

}  // namespace mpm::msg
