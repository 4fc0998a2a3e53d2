#include "daemon/mpmd/checkpoint.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstddef>
#include <cstring>
#include <filesystem>

#include "daemon/mpmd/state_io.hpp"

namespace mpm::checkpoint {
namespace {

constexpr char kMagic[8] = {'M', 'P', 'M', 'S', 'T', 'A', 'T', 'E'};
constexpr std::uint32_t kByteOrderMark = 0x01020304u;

struct Header {
  char magic[8];
  std::uint32_t version;
  std::uint32_t byte_order;
  std::uint64_t fingerprint;
  std::uint64_t payload_size;
  std::uint64_t checksum;
};
static_assert(sizeof(Header) == kHeaderSize, "the header is packed by its layout");
constexpr std::size_t kChecksummedHeader = offsetof(Header, checksum);

std::string errno_text() { return std::strerror(errno); }

bool write_all(int fd, const unsigned char* p, std::size_t n) {
  while (n > 0) {
    const ssize_t w = ::write(fd, p, n);
    if (w < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    p += w;
    n -= static_cast<std::size_t>(w);
  }
  return true;
}

bool fsync_folder(const std::string& path) {
  std::string folder = std::filesystem::path(path).parent_path().string();
  if (folder.empty()) folder = ".";
  const int fd = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return false;
  const bool ok = ::fsync(fd) == 0;
  ::close(fd);
  return ok;
}

}  // namespace

std::uint64_t fnv1a(const void* data, std::size_t size, std::uint64_t hash) noexcept {
  const auto* b = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < size; ++i) {
    hash ^= b[i];
    hash *= 0x100000001b3ull;
  }
  return hash;
}

std::vector<unsigned char> encode(MonitorService& service, std::uint64_t fingerprint) {
  std::vector<unsigned char> bytes(kHeaderSize, 0);
  state::StateWriter writer(bytes);
  service.visit_state(writer);
  Header h{};
  std::memcpy(h.magic, kMagic, sizeof kMagic);
  h.version = kVersion;
  h.byte_order = kByteOrderMark;
  h.fingerprint = fingerprint;
  h.payload_size = bytes.size() - kHeaderSize;
  const std::uint64_t head = fnv1a(&h, kChecksummedHeader);
  h.checksum = fnv1a(bytes.data() + kHeaderSize, bytes.size() - kHeaderSize, head);
  std::memcpy(bytes.data(), &h, sizeof h);
  return bytes;
}

bool write_atomically(const std::string& path, const std::vector<unsigned char>& bytes, std::string& error) {
  const std::string tmp = path + ".tmp";
  // 0600: the state says what the plant does; only the service reads it.
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
  if (fd < 0) {
    error = "cannot create " + tmp + ": " + errno_text();
    return false;
  }
  if (!write_all(fd, bytes.data(), bytes.size())) {
    error = "cannot write " + tmp + ": " + errno_text();
  } else if (::fsync(fd) != 0) {
    error = "cannot fsync " + tmp + ": " + errno_text();
  }
  if (::close(fd) != 0 && error.empty()) error = "cannot close " + tmp + ": " + errno_text();
  if (!error.empty()) {
    ::unlink(tmp.c_str());
    return false;
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    error = "cannot rename " + tmp + " to " + path + ": " + errno_text();
    ::unlink(tmp.c_str());
    return false;
  }
  if (!fsync_folder(path)) {
    // The file is in place; only its survival of a power cut is in doubt.
    error = "wrote " + path + " but could not fsync its folder: " + errno_text();
    return false;
  }
  return true;
}

Outcome decode(MonitorService& service, const std::vector<unsigned char>& bytes, std::uint64_t fingerprint,
               std::string& why) {
  if (bytes.size() < kHeaderSize) {
    why = "shorter than its header (" + std::to_string(bytes.size()) + " bytes)";
    return Outcome::kRefused;
  }
  Header h{};
  std::memcpy(&h, bytes.data(), sizeof h);
  if (std::memcmp(h.magic, kMagic, sizeof kMagic) != 0) {
    why = "not an mpmd checkpoint (no MPMSTATE header)";
    return Outcome::kRefused;
  }
  if (h.byte_order != kByteOrderMark) {
    why = "written on a machine of another byte order";
    return Outcome::kRefused;
  }
  if (h.version != kVersion) {
    why = "format version " + std::to_string(h.version) + ", this mpmd reads version " + std::to_string(kVersion);
    return Outcome::kRefused;
  }
  if (h.payload_size != bytes.size() - kHeaderSize) {
    why = "truncated or padded: the header announces " + std::to_string(h.payload_size) + " bytes of state, the file has " +
          std::to_string(bytes.size() - kHeaderSize);
    return Outcome::kRefused;
  }
  const std::uint64_t sum = fnv1a(bytes.data() + kHeaderSize, bytes.size() - kHeaderSize, fnv1a(&h, kChecksummedHeader));
  if (sum != h.checksum) {
    why = "checksum mismatch (the file is corrupt)";
    return Outcome::kRefused;
  }
  if (h.fingerprint != fingerprint) {
    why = "written for another plant file, controller or monitor settings";
    return Outcome::kOtherSetup;
  }
  state::StateReader reader(bytes.data() + kHeaderSize, bytes.size() - kHeaderSize);
  service.visit_state(reader);
  if (!reader.ok()) {
    why = "does not fit this monitor: " + reader.error();
    return Outcome::kRefused;
  }
  if (!reader.finished()) {
    why = "does not fit this monitor: " + std::to_string(bytes.size() - kHeaderSize - reader.position()) +
          " bytes of state left over";
    return Outcome::kRefused;
  }
  why = "resumed";
  return Outcome::kResumed;
}

Outcome load(MonitorService& service, const std::string& path, std::uint64_t fingerprint, std::string& why) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    if (errno == ENOENT) {
      why = "no checkpoint at " + path;
      return Outcome::kAbsent;
    }
    why = "cannot open " + path + ": " + errno_text();
    return Outcome::kRefused;
  }
  struct stat st {};
  std::vector<unsigned char> bytes;
  bool ok = ::fstat(fd, &st) == 0 && S_ISREG(st.st_mode);
  if (!ok) {
    why = path + " is not a regular file";
  } else if (static_cast<std::uint64_t>(st.st_size) > kMaxFileSize) {
    why = path + " is larger than any checkpoint (" + std::to_string(st.st_size) + " bytes)";
    ok = false;
  } else {
    bytes.resize(static_cast<std::size_t>(st.st_size));
    std::size_t got = 0;
    while (got < bytes.size()) {
      const ssize_t r = ::read(fd, bytes.data() + got, bytes.size() - got);
      if (r < 0 && errno == EINTR) continue;
      if (r <= 0) break;
      got += static_cast<std::size_t>(r);
    }
    bytes.resize(got);  // a file that shrank while read is caught as truncated
  }
  ::close(fd);
  if (!ok) return Outcome::kRefused;
  const Outcome outcome = decode(service, bytes, fingerprint, why);
  if (outcome != Outcome::kResumed) why = path + ": " + why;
  return outcome;
}

}  // namespace mpm::checkpoint
