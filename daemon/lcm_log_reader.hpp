// An `lcm-logger` file of our sample channel read as a recording, so that
// `mpm diagnose` and `mpm monitor` take a log as `--data` directly instead of
// replaying it through mpmd (formats.md section 4.4).
//
// OVERVIEW. Events are read by liblcm's own log reader (lcm_eventlog_*), and
// each sample by our checked decoder (lcm_wire.hpp), never by lcm-gen's: the
// file is as untrusted as the wire. liblcm allocates an event's channel and
// data from the lengths in its header before it reads them, so every header
// is checked first against the bytes the file has left and a cap; a file
// that lies about its framing is a located error (file, event number, byte
// offset), since nothing after a broken frame can be trusted. A frame that
// is sound but whose sample our decoder refuses is a counted drop, as mpmd
// counts a malformed datagram; events of other channels and samples of
// other controllers are skipped and counted. Nothing from the file is ever
// printed but numbers and names made of plain characters.
//
// Rows. The time column is not the sample's utime (a wall clock with the
// publisher's jitter) but its place in the controller's count of control
// intervals: t = (row index) x sample_time, a row per sequence number from
// the first sample. A sequence gap becomes rows of NaN (missing samples, as
// the monitor treats a gap); a repeated or older sequence number is dropped;
// a new session, or a jump beyond `max_gap_rows`, becomes one missing row.
// Columns: t, the plant's inputs and outputs, sim_<output> when any sample
// carries sim_y, then the samples' named extra signals (r_<output> among
// them: the setpoints `mpm replay` sends) in order of first appearance.
//
// Two passes: the first finds the columns (which extras and whether sim_y
// occur) and the controller; the second hands out rows. Memory does not
// grow with the log's length (one event at a time).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "config/plant_loader.hpp"
#include "config/row_source.hpp"

namespace mpm::transport {

// True when the file starts with LCM's event sync word (0xEDA1DA01): the
// format is told by content, not by the name. No UTF-8 text starts so.
bool is_lcm_log(const std::string& path);

struct LcmLogSettings {
  std::string channel = "MPM_SAMPLE";  // the sample channel (mpmd's lcm.sample_channel)
  std::string controller_id;           // empty: the first sample's controller
  std::int64_t max_gap_rows = 100000;  // a longer sequence jump is a resynchronisation
  std::uint32_t max_event_bytes = 64u << 20;  // larger frames are refused before liblcm reads them
};

struct LcmLogCounts {
  std::uint64_t events = 0;             // every event in the file
  std::uint64_t samples = 0;            // samples that became rows
  std::uint64_t other_channels = 0;     // events of other channels: skipped
  std::uint64_t other_controllers = 0;  // samples of another controller_id: skipped
  std::uint64_t malformed = 0;          // refused by the checked decoder: dropped
  std::uint64_t duplicates = 0;         // sequence number not after the last: dropped
  std::uint64_t restarts = 0;           // new session_id: one missing row
  std::uint64_t resyncs = 0;            // jump beyond max_gap_rows: one missing row
  std::uint64_t missing_rows = 0;       // rows of NaN for gaps, restarts and resyncs
  std::uint64_t extras_ignored = 0;     // extra values under an unusable or surplus name
  std::string first_malformed;          // "event 17 (byte 2210): n_u differs from ..."
};

class LcmLogRowReader final : public config::RowSource {
 public:
  // Scans the whole log once (columns, controller); throws ConfigError
  // naming the file and event for a broken frame, or when the log holds no
  // sample of the channel and controller.
  LcmLogRowReader(const std::string& path, const PlantModel& plant, const LcmLogSettings& settings = {});
  ~LcmLogRowReader() override;

  const std::vector<std::string>& names() const override { return names_; }
  const std::string& source() const override { return path_; }
  bool next(std::vector<double>& row) override;
  std::string notes() const override;
  const LcmLogCounts& counts() const;

 private:
  struct Impl;
  std::string path_;
  std::vector<std::string> names_;
  std::unique_ptr<Impl> impl_;
};

// The whole log as a Recording (the same rows LcmLogRowReader hands out).
// `counts`, when given, receives what was skipped.
config::Recording load_lcm_log(const std::string& path, const PlantModel& plant, const LcmLogSettings& settings = {},
                               LcmLogCounts* counts = nullptr);

}  // namespace mpm::transport
