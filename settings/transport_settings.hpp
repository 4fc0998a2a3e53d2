// Which transport to use and how it is named on the wire. Plain data with the
// defaults of the README, so config files only say what differs.
#pragma once

#include <cstdint>
#include <string>

namespace mpm::transport {

enum class Kind { kLcm, kDds };

struct LcmSettings {
  // Default LCM URL: multicast with ttl=0 keeps the traffic on this host.
  std::string url = "udpm://239.255.76.67:7667?ttl=0";
  std::string sample_channel = "MPM_SAMPLE";
  std::string alarm_channel = "MPM_ALARM";
  std::string status_channel = "MPM_STATUS";
  std::string diagnosis_channel = "MPM_DIAGNOSIS";
  bool operator==(const LcmSettings&) const = default;
};

struct DdsSettings {
  int domain = 0;           // DDS domain id, 0..230
  // Cyclone DDS configuration: a file path, a file:// URI or inline XML.
  // Empty = Cyclone's own default (CYCLONEDDS_URI if set).
  std::string config;
  std::string sample_topic = "mpm_sample";
  std::string alarm_topic = "mpm_alarm";
  std::string status_topic = "mpm_status";
  std::string diagnosis_topic = "mpm_diagnosis";
  int sample_history = 64;  // KEEP_LAST depth of sample writer and reader
  bool operator==(const DdsSettings&) const = default;
};

// What a received sample may contain. Every length on the wire is checked
// against these (and against the bytes that remain) before anything is
// allocated, so a hostile or broken publisher cannot make the receiver grow:
// the memory a sample takes is bounded by the plant's dimensions.
struct SampleLimits {
  std::uint32_t n_u = 0;             // inputs the plant has; 0 = any up to max_channels
  std::uint32_t n_y = 0;             // outputs (sim_y: 0 or n_y); 0 = any up to max_channels
  std::uint32_t max_channels = 1024; // bound of u and y when the plant is not known (mpm listen)
  std::uint32_t max_extra = 256;     // named extra signals
  std::uint32_t max_string = 256;    // bytes of controller_id and of each extra name
  bool operator==(const SampleLimits&) const = default;
};

struct Settings {
  Kind kind = Kind::kLcm;
  SampleLimits sample_limits;  // set by mpmd from its plant
  LcmSettings lcm;
  DdsSettings dds;
  bool operator==(const Settings&) const = default;  // a reload compares them
};

inline const char* to_string(Kind kind) noexcept { return kind == Kind::kDds ? "dds" : "lcm"; }

// "lcm" / "dds"; false (kind unchanged) for anything else.
inline bool parse_kind(const std::string& text, Kind& kind) noexcept {
  if (text != "lcm" && text != "dds") return false;
  kind = text == "dds" ? Kind::kDds : Kind::kLcm;
  return true;
}

}  // namespace mpm::transport
