// Writing lcm-logger files in tests, through liblcm's own writer
// (lcm_eventlog_write_event), with samples encoded by lcm-gen's encoder:
// what `lcm-logger` records of an MPC publishing on MPM_SAMPLE.
#pragma once

#include <lcm/eventlog.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "config/plant_loader.hpp"
#include "transport/lcm_codec.hpp"
#include "transport/messages.hpp"

namespace mpm::test {

struct LogEvent {
  std::string channel;
  std::vector<std::uint8_t> data;
};

inline std::vector<std::uint8_t> encode_sample(const msg::Sample& s) {
  mpm_lcm::sample_t wire;
  transport::lcm_codec::to_wire(s, wire);
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(wire.getEncodedSize()));
  wire.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
  return bytes;
}

inline void write_lcm_log(const std::string& path, const std::vector<LogEvent>& events) {
  lcm_eventlog_t* log = lcm_eventlog_create(path.c_str(), "w");
  if (!log) throw std::runtime_error("cannot write " + path);
  std::int64_t utime = 1700000000000000;
  for (const LogEvent& e : events) {
    lcm_eventlog_event_t ev{};
    ev.timestamp = utime += 1000;
    ev.channellen = static_cast<std::int32_t>(e.channel.size());
    ev.datalen = static_cast<std::int32_t>(e.data.size());
    ev.channel = const_cast<char*>(e.channel.c_str());
    ev.data = const_cast<std::uint8_t*>(e.data.data());
    lcm_eventlog_write_event(log, &ev);
  }
  lcm_eventlog_destroy(log);
}

// One sample per row of `rec` as `mpm replay` publishes it: u and y in plant
// order, every column other than t, inputs and outputs as a named extra.
inline std::vector<msg::Sample> samples_of(const PlantModel& plant, const config::Recording& rec) {
  const config::BoundRecording b = config::bind(plant, rec);
  std::vector<std::size_t> extra = b.extra;
  for (std::size_t j = 0; j < plant.n_outputs(); ++j)
    if (b.setpoints[j]) extra.push_back(*b.setpoints[j]);
  std::vector<msg::Sample> out;
  for (Eigen::Index k = 0; k < rec.data.rows(); ++k) {
    msg::Sample s;
    s.controller_id = "column-7";
    s.session_id = 77;
    s.seq = k + 1;
    s.utime = 1700000000000000 + k * 1000003;  // a wall clock with jitter: not the time column
    for (const std::size_t c : b.inputs) s.u.push_back(rec.data(k, static_cast<Eigen::Index>(c)));
    for (const std::size_t c : b.outputs) s.y.push_back(rec.data(k, static_cast<Eigen::Index>(c)));
    for (const std::size_t c : extra) {
      s.extra_names.push_back(rec.names[c]);
      s.extra_values.push_back(rec.data(k, static_cast<Eigen::Index>(c)));
    }
    out.push_back(std::move(s));
  }
  return out;
}

}  // namespace mpm::test
