// Messages with every field set to something recognisable, for round trips.
#pragma once

#include <limits>

#include "transport/messages.hpp"

namespace mpm::test {

inline msg::Sample full_sample() {
  msg::Sample s;
  s.controller_id = "column-7";
  s.session_id = 0x1234567890ll;
  s.seq = 4242;
  s.utime = 1700000000123456ll;
  s.u = {1.5, -2.25, 3.0};
  s.y = {90.125, 5.5};
  s.sim_y = {90.0, 5.25};
  s.extra_names = {"feed_flow", "r_y1"};
  s.extra_values = {2.5, 90.0};
  return s;
}

inline msg::Alarm full_alarm() {
  msg::Alarm a;
  a.controller_id = "column-7";
  a.utime = 1700000000999999ll;
  a.sample_sequence = 4300;
  a.output = "y2";
  a.input = "u1";
  a.output_index = 1;
  a.input_index = 0;
  a.raised = true;
  a.f = 0.0353;
  a.p_value = 1e-9;
  a.gamma = 0.0025;
  a.physics = "gain";
  a.text = "model-plant mismatch on u1 -> y2";
  return a;
}

inline msg::Status full_status() {
  msg::Status s;
  s.controller_id = "column-7";
  s.utime = 1700000001000000ll;
  s.uptime_ms = 3600000;
  s.ready = true;
  s.effective_samples = 999.5;
  s.raise_threshold = 29.59;
  s.clear_threshold = 14.79;
  s.samples_seen = 10;
  s.samples_used = 9;
  s.dropped = 1;
  s.gaps = 2;
  s.missing = 3;
  s.duplicates = 4;
  s.out_of_order = 5;
  s.restarts = 6;
  s.malformed = 7;
  s.nan_samples = 8;
  s.alarms_raised = 1;
  s.channels = {{"y1", "u1", 0.001, 0.002, 1.5, 0.9, 0.2, false},
                {"y2", "u1", 0.035, 0.03, 60.0, 1e-9, std::numeric_limits<double>::quiet_NaN(), true}};
  s.loops = {{"y1", 2.8, 1.02, 1.0, false, false}, {"y2", 5.3, 1.05, 1.0, true, false}};
  return s;
}


}  // namespace mpm::test
