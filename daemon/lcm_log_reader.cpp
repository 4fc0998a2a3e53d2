#include "daemon/lcm_log_reader.hpp"

#include <lcm/eventlog.h>
#include <sys/stat.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>
#include <string_view>

#include "transport/lcm_wire.hpp"
#include "transport/messages.hpp"

namespace mpm::transport {
namespace {

using config::ConfigError;

constexpr std::uint32_t kSyncWord = 0xEDA1DA01u;  // LCM's event marker (eventlog.c)
constexpr std::size_t kHeaderBytes = 4 + 8 + 8 + 4 + 4;  // sync, eventnum, timestamp, channel and data lengths
constexpr std::size_t kMaxNameBytes = 64;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::uint32_t big_endian32(const unsigned char* p) {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) | p[3];
}

// Names from the file become column names and appear in messages and in the
// HTML report: only plain characters are taken as they are.
bool plain_name(std::string_view name) {
  if (name.empty() || name.size() > kMaxNameBytes) return false;
  for (const char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    std::strchr("_.:/+-", c) != nullptr;
    if (!ok) return false;
  }
  return true;
}

// For a message: plain characters kept, anything else as '?', cut at 64.
std::string printable(std::string_view text) {
  std::string out;
  for (const char c : text.substr(0, kMaxNameBytes)) out += (c >= 0x20 && c < 0x7f) ? c : '?';
  if (text.size() > kMaxNameBytes) out += "...";
  return out;
}

struct EventFree {
  void operator()(lcm_eventlog_event_t* e) const noexcept { lcm_eventlog_free_event(e); }
};
struct LogClose {
  void operator()(lcm_eventlog_t* l) const noexcept { lcm_eventlog_destroy(l); }
};
using EventPtr = std::unique_ptr<lcm_eventlog_event_t, EventFree>;

// The events of one log, in order, handed out as decoded samples of the
// channel and controller; everything else counted.
class EventCursor {
 public:
  EventCursor(const std::string& path, const LcmLogSettings& settings, const SampleLimits& limits)
      : path_(path), settings_(settings), limits_(limits) {
    struct stat info {};
    if (::stat(path.c_str(), &info) != 0)
      throw ConfigError(path + ": cannot open file: " + std::strerror(errno));
    if (!S_ISREG(info.st_mode))
      throw ConfigError(path + ": not a regular file (a device, FIFO or directory is not read)");
    size_ = static_cast<std::uint64_t>(info.st_size);
    log_.reset(lcm_eventlog_create(path.c_str(), "r"));
    if (!log_) throw ConfigError(path + ": cannot open file: " + std::strerror(errno));
  }

  // The next sample of the channel (and controller, once known) into `s`;
  // false at the end of the file. `controller` is fixed by the first sample
  // when empty.
  bool next_sample(msg::Sample& s, std::string& controller, LcmLogCounts& c) {
    for (;;) {
      EventPtr event = next_event(c);
      if (!event) return false;
      const std::string_view channel(event->channel, static_cast<std::size_t>(event->channellen));
      if (channel != settings_.channel) {
        ++c.other_channels;
        if (channels_seen_.size() < 5) channels_seen_.emplace(printable(channel), 0);
        continue;
      }
      const WireError e =
          decode_lcm_sample(event->data, static_cast<std::size_t>(event->datalen), limits_, s);
      if (e != WireError::kNone) {
        if (c.malformed++ == 0) c.first_malformed = at() + describe(e);
        continue;
      }
      if (controller.empty()) controller = s.controller_id;
      if (s.controller_id != controller) {
        ++c.other_controllers;
        continue;
      }
      return true;
    }
  }

  std::string channels_seen() const {
    std::string out;
    for (const auto& [name, unused] : channels_seen_) out += (out.empty() ? "" : ", ") + name;
    return out.empty() ? "none" : out;
  }

 private:
  std::string at() const {
    return "event " + std::to_string(event_) + " (byte " + std::to_string(offset_) + "): ";
  }
  [[noreturn]] void fail(const std::string& what) const { throw ConfigError(path_ + ": " + at() + what); }

  // The frame at the current offset, checked before liblcm allocates from
  // its lengths; null at a clean end of the file.
  EventPtr next_event(LcmLogCounts& c) {
    std::FILE* f = log_->f;
    const off_t here = ::ftello(f);
    if (here < 0) throw ConfigError(path_ + ": cannot read file: " + std::strerror(errno));
    offset_ = static_cast<std::uint64_t>(here);
    ++event_;
    const std::uint64_t left = offset_ < size_ ? size_ - offset_ : 0;
    if (left == 0) return nullptr;
    unsigned char h[kHeaderBytes];
    if (left < kHeaderBytes || std::fread(h, 1, kHeaderBytes, f) != kHeaderBytes)
      fail("truncated: " + std::to_string(left) + " bytes left where an event header needs " +
           std::to_string(kHeaderBytes));
    if (big_endian32(h) != kSyncWord)
      fail("no event sync word here: the file is not an LCM log from this point (corrupt or not a log)");
    const auto channel_len = static_cast<std::int32_t>(big_endian32(h + 20));
    const auto data_len = static_cast<std::int32_t>(big_endian32(h + 24));
    if (channel_len <= 0 || channel_len >= 1000)
      fail("channel name length " + std::to_string(channel_len) + " outside 1..999");
    if (data_len < 0 || static_cast<std::uint32_t>(data_len) > settings_.max_event_bytes)
      fail("data length " + std::to_string(data_len) + " outside 0.." + std::to_string(settings_.max_event_bytes));
    const std::uint64_t frame = kHeaderBytes + static_cast<std::uint64_t>(channel_len) + static_cast<std::uint64_t>(data_len);
    if (frame > left)
      fail("truncated: the event announces " + std::to_string(frame) + " bytes, the file has " + std::to_string(left) +
           " left");
    check_next_sync(here, frame, left);
    if (::fseeko(f, here, SEEK_SET) != 0) throw ConfigError(path_ + ": cannot seek: " + std::strerror(errno));
    EventPtr event(lcm_eventlog_read_next_event(log_.get()));
    if (!event) fail("liblcm could not read the event");
    ++c.events;
    return event;
  }

  // liblcm refuses an event unless the file ends after it or the next sync
  // word follows: checked here first, so the error names the next event.
  void check_next_sync(off_t here, std::uint64_t frame, std::uint64_t left) {
    if (frame == left) return;
    unsigned char magic[4];
    const bool read = ::fseeko(log_->f, here + static_cast<off_t>(frame), SEEK_SET) == 0 &&
                      std::fread(magic, 1, 4, log_->f) == 4;
    if (read && big_endian32(magic) == kSyncWord) return;
    ++event_;
    offset_ += frame;
    if (!read) fail("truncated: " + std::to_string(left - frame) + " bytes left where an event header needs " +
                    std::to_string(kHeaderBytes));
    fail("no event sync word here: the file is not an LCM log from this point (corrupt or not a log)");
  }

  std::string path_;
  const LcmLogSettings& settings_;
  SampleLimits limits_;
  std::unique_ptr<lcm_eventlog_t, LogClose> log_;
  std::uint64_t size_ = 0;
  std::uint64_t event_ = 0;   // 1-based number of the event being read
  std::uint64_t offset_ = 0;  // its byte offset
  std::map<std::string, int> channels_seen_;
};

SampleLimits limits_of(const PlantModel& plant) {
  SampleLimits l;
  l.n_u = static_cast<std::uint32_t>(plant.n_inputs());
  l.n_y = static_cast<std::uint32_t>(plant.n_outputs());
  return l;
}

}  // namespace

bool is_lcm_log(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return false;
  unsigned char magic[4];
  const bool is_log = std::fread(magic, 1, 4, f) == 4 && big_endian32(magic) == kSyncWord;
  std::fclose(f);
  return is_log;
}

struct LcmLogRowReader::Impl {
  Impl(const std::string& path, const PlantModel& plant, const LcmLogSettings& s)
      : settings(s), limits(limits_of(plant)), cursor(path, settings, limits), controller(s.controller_id),
        ts(plant.sample_time), m(plant.n_inputs()), p(plant.n_outputs()) {}

  LcmLogSettings settings;
  SampleLimits limits;
  EventCursor cursor;
  std::string controller;
  double ts;
  std::size_t m, p;
  bool with_sim = false;
  std::map<std::string, std::size_t, std::less<>> extra_column;
  LcmLogCounts counts;
  msg::Sample sample, held;
  bool started = false, has_held = false;
  std::int64_t session = 0, last_seq = 0;
  std::uint64_t gap_left = 0, row_index = 0;

  void fill(const msg::Sample* s, std::size_t columns, std::vector<double>& row) {
    row.assign(columns, kNaN);
    row[0] = static_cast<double>(row_index++) * ts;
    if (!s) return;
    auto put = [&row](std::size_t col, double v) { row[col] = std::isfinite(v) ? v : kNaN; };
    for (std::size_t i = 0; i < m; ++i) put(1 + i, s->u[i]);
    for (std::size_t j = 0; j < p; ++j) put(1 + m + j, s->y[j]);
    if (with_sim && s->sim_y.size() == p)
      for (std::size_t j = 0; j < p; ++j) put(1 + m + p + j, s->sim_y[j]);
    for (std::size_t e = 0; e < s->extra_names.size(); ++e) {
      const auto it = extra_column.find(s->extra_names[e]);
      if (it == extra_column.end()) {
        ++counts.extras_ignored;
        continue;
      }
      put(it->second, s->extra_values[e]);
    }
    ++counts.samples;
  }

  // Missing rows before `s`: a new session or a jump too long to fill is
  // one, a gap is its length; 0 means in order. Negative: drop `s`.
  std::int64_t rows_before(const msg::Sample& s) {
    if (!started || s.session_id != session) {
      if (started) ++counts.restarts;
      const std::int64_t rows = started ? 1 : 0;
      started = true;
      session = s.session_id;
      last_seq = s.seq;
      return rows;
    }
    if (s.seq <= last_seq) {
      ++counts.duplicates;
      return -1;
    }
    // s.seq > last_seq: the difference fits in 64 unsigned bits whatever the signs.
    const std::uint64_t step = static_cast<std::uint64_t>(s.seq) - static_cast<std::uint64_t>(last_seq);
    last_seq = s.seq;
    if (step - 1 > static_cast<std::uint64_t>(settings.max_gap_rows)) {
      ++counts.resyncs;
      return 1;
    }
    return static_cast<std::int64_t>(step - 1);
  }
};

LcmLogRowReader::LcmLogRowReader(const std::string& path, const PlantModel& plant, const LcmLogSettings& settings)
    : path_(path) {
  // Pass 1: the columns and the controller.
  Impl scan(path, plant, settings);
  names_.push_back("t");
  names_.insert(names_.end(), plant.inputs.begin(), plant.inputs.end());
  names_.insert(names_.end(), plant.outputs.begin(), plant.outputs.end());
  std::vector<std::string> extras;
  std::map<std::string, int, std::less<>> taken;
  for (const auto& n : names_) taken.emplace(n, 0);
  for (const auto& y : plant.outputs) taken.emplace("sim_" + y, 0);
  bool any = false;
  while (scan.cursor.next_sample(scan.sample, scan.controller, scan.counts)) {
    any = true;
    scan.with_sim = scan.with_sim || scan.sample.sim_y.size() == plant.n_outputs();
    for (const auto& name : scan.sample.extra_names)
      if (extras.size() < scan.limits.max_extra && plain_name(name) && taken.emplace(name, 0).second)
        extras.push_back(name);
  }
  if (!any) {
    std::string why = path + ": no sample of channel '" + settings.channel + "'" +
                      (settings.controller_id.empty() ? "" : " from controller '" + printable(settings.controller_id) + "'") +
                      " in " + std::to_string(scan.counts.events) + " events (other channels: " +
                      scan.cursor.channels_seen() + ")";
    if (scan.counts.malformed)
      why += "; " + std::to_string(scan.counts.malformed) + " malformed samples, the first at " +
             scan.counts.first_malformed;
    throw ConfigError(why);
  }
  // Pass 2 reads the rows.
  impl_ = std::make_unique<Impl>(path, plant, settings);
  impl_->controller = scan.controller;
  impl_->with_sim = scan.with_sim;
  if (impl_->with_sim)
    for (const auto& y : plant.outputs) names_.push_back("sim_" + y);
  for (const auto& name : extras) {
    impl_->extra_column.emplace(name, names_.size());
    names_.push_back(name);
  }
}

LcmLogRowReader::~LcmLogRowReader() = default;

const LcmLogCounts& LcmLogRowReader::counts() const { return impl_->counts; }

bool LcmLogRowReader::next(std::vector<double>& row) {
  Impl& d = *impl_;
  if (d.gap_left > 0) {
    --d.gap_left;
    d.fill(nullptr, names_.size(), row);
    return true;
  }
  if (d.has_held) {
    d.has_held = false;
    d.fill(&d.held, names_.size(), row);
    return true;
  }
  while (d.cursor.next_sample(d.sample, d.controller, d.counts)) {
    const std::int64_t missing = d.rows_before(d.sample);
    if (missing < 0) continue;
    if (missing == 0) {
      d.fill(&d.sample, names_.size(), row);
      return true;
    }
    d.counts.missing_rows += static_cast<std::uint64_t>(missing);
    std::swap(d.held, d.sample);  // reused storage: no allocation once both are sized
    d.has_held = true;
    d.gap_left = static_cast<std::uint64_t>(missing) - 1;
    d.fill(nullptr, names_.size(), row);
    return true;
  }
  return false;
}

std::string LcmLogRowReader::notes() const {
  const LcmLogCounts& c = impl_->counts;
  std::string out = path_ + ": LCM log, " + std::to_string(c.samples) + " samples of " + impl_->settings.channel +
                    " from controller '" + printable(impl_->controller) + "' in " + std::to_string(c.events) +
                    " events";
  const std::pair<const char*, std::uint64_t> skipped[] = {
      {"events of other channels skipped", c.other_channels},
      {"samples of other controllers skipped", c.other_controllers},
      {"repeated or old sequence numbers dropped", c.duplicates},
      {"session restarts", c.restarts},
      {"sequence jumps resynchronised", c.resyncs},
      {"missing rows for gaps", c.missing_rows},
      {"extra values ignored (name unusable or beyond 256)", c.extras_ignored},
      {"malformed samples dropped", c.malformed}};
  for (const auto& [what, n] : skipped)
    if (n) out += "; " + std::to_string(n) + " " + what;
  if (c.malformed) out += " (the first at " + c.first_malformed + ")";
  return out;
}

config::Recording load_lcm_log(const std::string& path, const PlantModel& plant, const LcmLogSettings& settings,
                               LcmLogCounts* counts) {
  LcmLogRowReader reader(path, plant, settings);
  config::Recording rec = config::read_rows(reader);
  if (counts) *counts = reader.counts();
  return rec;
}

}  // namespace mpm::transport
