// OVERVIEW
// mpmd's checkpoint: the monitor service's state in one file, so a restart
// (a crash, SIGKILL, a reboot) goes on from where it was instead of spending
// the warm-up and the memory of the forgetting window again, and alarms that
// were raised stay raised.
//
// Written atomically as chrony writes its drift file: the whole file to
// PATH.tmp, fsync, rename over PATH, fsync the folder. A reader therefore sees
// the old file or the new one, never half of one, even across a power cut.
//
// Layout (machine byte order; the header says which):
//   "MPMSTATE"                    8 bytes
//   format version                u32 (kVersion)
//   byte-order mark 0x01020304    u32
//   setup fingerprint             u64: FNV-1a of the controller, the monitor
//                                 settings and the plant file's text
//   payload size                  u64
//   checksum                      u64: FNV-1a of the 32 bytes above and the payload
//   payload                       MonitorService::visit_state through StateWriter
//
// Loading trusts nothing: the size, magic, version, byte order and checksum
// are checked before any of the payload is used, and every array's size in
// it is checked against the service that setup built (state_io.hpp). A file
// of another plant or settings (fingerprint) is not an error: the service
// starts fresh and says why.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "daemon/mpmd/monitor_service.hpp"

namespace mpm::checkpoint {

// 2: the regressor bank's current fill wait (after a gap, or at the first start).
constexpr std::uint32_t kVersion = 2;
constexpr std::size_t kHeaderSize = 40;
// Larger files are refused before they are read (a 50 x 50 plant's state
// with the default orders is about 200 MB).
constexpr std::uint64_t kMaxFileSize = std::uint64_t{4} << 30;

std::uint64_t fnv1a(const void* data, std::size_t size, std::uint64_t hash = 0xcbf29ce484222325ull) noexcept;

// The file's bytes for the service's current state.
std::vector<unsigned char> encode(MonitorService& service, std::uint64_t fingerprint);

// Writes `bytes` to `path` atomically (see the overview). False and `error`
// (naming the path and the failing step) on failure; PATH is then unchanged.
bool write_atomically(const std::string& path, const std::vector<unsigned char>& bytes, std::string& error);

enum class Outcome {
  kResumed,     // the state was loaded into the service
  kAbsent,      // no file: a first start
  kOtherSetup,  // written for another plant or other settings: ignored
  kRefused,     // corrupt, truncated, another format: ignored; the service
                // may be partly overwritten and must be rebuilt
};

// Loads the state at `path` into `service` when its fingerprint is
// `fingerprint`. `why` says what happened, for the log.
Outcome load(MonitorService& service, const std::string& path, std::uint64_t fingerprint, std::string& why);

// The same from bytes already read (tests).
Outcome decode(MonitorService& service, const std::vector<unsigned char>& bytes, std::uint64_t fingerprint,
               std::string& why);

}  // namespace mpm::checkpoint
