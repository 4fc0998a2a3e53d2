#include "transport/lcm_wire.hpp"

#include <cstring>

// Only for the types' fingerprints: the generated decoders are not used on
// received bytes (see the header).
#include <mpm_lcm/alarm_t.hpp>
#include <mpm_lcm/diagnosis_t.hpp>
#include <mpm_lcm/sample_t.hpp>
#include <mpm_lcm/status_t.hpp>

namespace mpm::transport {

namespace {

// Bounds-checked big-endian reads over the received bytes. Every read checks
// what remains first; a failed read leaves the position unchanged.
class Reader {
 public:
  Reader(const void* data, std::size_t size) noexcept : p_(static_cast<const unsigned char*>(data)), left_(size) {}

  std::size_t left() const noexcept { return left_; }

  bool u64(std::uint64_t& v) noexcept {
    if (left_ < 8) return false;
    v = 0;
    for (int i = 0; i < 8; ++i) v = (v << 8) | p_[i];
    advance(8);
    return true;
  }
  bool i64(std::int64_t& v) noexcept {
    std::uint64_t u = 0;
    if (!u64(u)) return false;
    v = static_cast<std::int64_t>(u);  // two's complement, defined since C++20
    return true;
  }
  bool i32(std::int32_t& v) noexcept {
    if (left_ < 4) return false;
    const std::uint32_t u = (std::uint32_t{p_[0]} << 24) | (std::uint32_t{p_[1]} << 16) |
                            (std::uint32_t{p_[2]} << 8) | std::uint32_t{p_[3]};
    v = static_cast<std::int32_t>(u);
    advance(4);
    return true;
  }
  bool f64(double& v) noexcept {
    std::uint64_t u = 0;
    if (!u64(u)) return false;
    std::memcpy(&v, &u, sizeof v);
    return true;
  }
  bool skip(std::size_t n) noexcept {
    if (left_ < n) return false;
    advance(n);
    return true;
  }
  // A string: int32 length counting the NUL, the bytes, the NUL. Sets
  // `chars` and `length` (without the NUL) only when it is well formed.
  WireError string(const char*& chars, std::size_t& length, std::uint32_t max_string) noexcept {
    std::int32_t n = 0;
    if (!i32(n)) return WireError::kTruncated;
    if (n < 1) return WireError::kBadLength;
    const auto bytes = static_cast<std::size_t>(n);
    if (bytes - 1 > max_string) return WireError::kStringTooLong;
    if (bytes > left_) return WireError::kTruncated;
    if (p_[bytes - 1] != 0) return WireError::kBadLength;
    chars = reinterpret_cast<const char*>(p_);
    length = bytes - 1;
    advance(bytes);
    return WireError::kNone;
  }
  WireError skip_string(std::uint32_t max_string) noexcept {
    const char* chars = nullptr;
    std::size_t length = 0;
    return string(chars, length, max_string);
  }
  // An int32 array length, checked to be >= 0 and to fit `element_bytes`
  // each in what remains.
  WireError count(std::int32_t& n, std::size_t element_bytes) noexcept {
    if (!i32(n)) return WireError::kTruncated;
    if (n < 0) return WireError::kBadLength;
    if (static_cast<std::size_t>(n) > left_ / element_bytes) return WireError::kTruncated;
    return WireError::kNone;
  }

 private:
  void advance(std::size_t n) noexcept {
    p_ += n;
    left_ -= n;
  }
  const unsigned char* p_;
  std::size_t left_;
};

WireError fingerprint(Reader& r, std::int64_t expected) noexcept {
  std::int64_t hash = 0;
  if (!r.i64(hash)) return WireError::kTruncated;
  return hash == expected ? WireError::kNone : WireError::kFingerprint;
}

// Reads `n` doubles into `out` (resized to n: within capacity once sized).
bool read_doubles(Reader& r, std::size_t n, std::vector<double>& out) {
  out.resize(n);
  for (double& x : out) {
    if (!r.f64(x)) return false;
  }
  return true;
}

// Smallest encoded size of an extra: a name of length 0 (int32 + NUL) and
// its value.
constexpr std::size_t kMinExtraBytes = 4 + 1 + 8;
constexpr std::size_t kMinChannelBytes = 2 * (4 + 1) + 5 * 8 + 1;
constexpr std::size_t kMinLoopBytes = (4 + 1) + 3 * 8 + 2;

#define MPM_WIRE_TRY(expr)                          \
  do {                                              \
    const WireError wire_error_ = (expr);           \
    if (wire_error_ != WireError::kNone) return wire_error_; \
  } while (false)

WireError need(bool ok) noexcept { return ok ? WireError::kNone : WireError::kTruncated; }

// n against the plant's dimension (or the general cap when it is not known).
bool dimension_ok(std::int32_t n, std::uint32_t expected, std::uint32_t cap) noexcept {
  const auto count = static_cast<std::uint32_t>(n);
  return expected != 0 ? count == expected : count <= cap;
}

}  // namespace

const char* describe(WireError error) noexcept {
  switch (error) {
    case WireError::kNone: return "valid";
    case WireError::kTruncated: return "a field runs past the end of the message";
    case WireError::kFingerprint: return "wrong type fingerprint";
    case WireError::kBadLength: return "a negative length or a string without its terminating NUL";
    case WireError::kStringTooLong: return "a string longer than allowed";
    case WireError::kWrongInputs: return "the number of inputs differs from the plant's";
    case WireError::kWrongOutputs: return "the number of outputs differs from the plant's";
    case WireError::kWrongSimOutputs: return "the number of simulated outputs is neither 0 nor the outputs'";
    case WireError::kTooManyExtras: return "more extra signals than allowed";
    case WireError::kTrailingBytes: return "bytes after the last field";
  }
  return "unknown";
}

WireError decode_lcm_sample(const void* data, std::size_t size, const SampleLimits& limits, msg::Sample& out) {
  Reader r(data, size);
  MPM_WIRE_TRY(fingerprint(r, mpm_lcm::sample_t::getHash()));
  const char* chars = nullptr;
  std::size_t length = 0;
  MPM_WIRE_TRY(r.string(chars, length, limits.max_string));
  out.controller_id.assign(chars, length);
  MPM_WIRE_TRY(need(r.i64(out.session_id) && r.i64(out.seq) && r.i64(out.utime)));

  std::int32_t n_u = 0;
  MPM_WIRE_TRY(r.count(n_u, 8));
  if (!dimension_ok(n_u, limits.n_u, limits.max_channels)) return WireError::kWrongInputs;
  MPM_WIRE_TRY(need(read_doubles(r, static_cast<std::size_t>(n_u), out.u)));

  std::int32_t n_y = 0;
  MPM_WIRE_TRY(r.count(n_y, 8));
  if (!dimension_ok(n_y, limits.n_y, limits.max_channels)) return WireError::kWrongOutputs;
  MPM_WIRE_TRY(need(read_doubles(r, static_cast<std::size_t>(n_y), out.y)));

  std::int32_t n_sim = 0;
  MPM_WIRE_TRY(r.count(n_sim, 8));
  if (n_sim != 0 && n_sim != n_y) return WireError::kWrongSimOutputs;
  // Assigned even when empty: a reused message must not keep the previous
  // sample's prediction (LCM 1.3's decoder skips zero-length arrays).
  MPM_WIRE_TRY(need(read_doubles(r, static_cast<std::size_t>(n_sim), out.sim_y)));

  std::int32_t n_extra = 0;
  MPM_WIRE_TRY(r.count(n_extra, kMinExtraBytes));
  if (static_cast<std::uint32_t>(n_extra) > limits.max_extra) return WireError::kTooManyExtras;
  const auto extras = static_cast<std::size_t>(n_extra);
  out.extra_names.resize(extras);
  for (std::string& name : out.extra_names) {
    MPM_WIRE_TRY(r.string(chars, length, limits.max_string));
    name.assign(chars, length);
  }
  MPM_WIRE_TRY(need(read_doubles(r, extras, out.extra_values)));
  return r.left() == 0 ? WireError::kNone : WireError::kTrailingBytes;
}

WireError check_lcm_alarm(const void* data, std::size_t size, std::uint32_t max_string) noexcept {
  Reader r(data, size);
  MPM_WIRE_TRY(fingerprint(r, mpm_lcm::alarm_t::getHash()));
  MPM_WIRE_TRY(r.skip_string(max_string));                       // controller_id
  MPM_WIRE_TRY(need(r.skip(2 * 8)));                             // utime, sample_sequence
  MPM_WIRE_TRY(r.skip_string(max_string));                       // output
  MPM_WIRE_TRY(r.skip_string(max_string));                       // input
  MPM_WIRE_TRY(need(r.skip(2 * 4 + 1 + 3 * 8)));                 // indices, raised, f, p, gamma
  MPM_WIRE_TRY(r.skip_string(max_string));                       // physics
  MPM_WIRE_TRY(r.skip_string(max_string * 4));                   // text: one line for people
  return r.left() == 0 ? WireError::kNone : WireError::kTrailingBytes;
}

WireError check_lcm_status(const void* data, std::size_t size, std::uint32_t max_string,
                           std::uint32_t max_items) noexcept {
  Reader r(data, size);
  MPM_WIRE_TRY(fingerprint(r, mpm_lcm::status_t::getHash()));
  MPM_WIRE_TRY(r.skip_string(max_string));            // controller_id
  MPM_WIRE_TRY(need(r.skip(2 * 8 + 1 + 3 * 8 + 11 * 8)));  // utime .. alarms_raised
  std::int32_t n = 0;
  MPM_WIRE_TRY(r.count(n, kMinChannelBytes));
  if (static_cast<std::uint32_t>(n) > max_items) return WireError::kTooManyExtras;
  for (std::int32_t i = 0; i < n; ++i) {
    MPM_WIRE_TRY(r.skip_string(max_string));  // output
    MPM_WIRE_TRY(r.skip_string(max_string));  // input
    MPM_WIRE_TRY(need(r.skip(5 * 8 + 1)));
  }
  MPM_WIRE_TRY(r.count(n, kMinLoopBytes));
  if (static_cast<std::uint32_t>(n) > max_items) return WireError::kTooManyExtras;
  for (std::int32_t i = 0; i < n; ++i) {
    MPM_WIRE_TRY(r.skip_string(max_string));
    MPM_WIRE_TRY(need(r.skip(3 * 8 + 2)));
  }
  return r.left() == 0 ? WireError::kNone : WireError::kTrailingBytes;
}

WireError check_lcm_diagnosis(const void* data, std::size_t size, std::uint32_t max_string,
                              std::uint32_t max_items) noexcept {
  Reader r(data, size);
  MPM_WIRE_TRY(fingerprint(r, mpm_lcm::diagnosis_t::getHash()));
  MPM_WIRE_TRY(r.skip_string(max_string));                       // controller_id
  MPM_WIRE_TRY(need(r.skip(2 * 8)));                             // utime, sample_sequence
  MPM_WIRE_TRY(r.skip_string(max_string));                       // output
  MPM_WIRE_TRY(r.skip_string(max_string));                       // input
  MPM_WIRE_TRY(need(r.skip(3 * 4 + 1)));                         // indices, window, found
  MPM_WIRE_TRY(r.skip_string(max_string));                       // physics
  MPM_WIRE_TRY(r.skip_string(max_string * 4));                   // channels
  std::int32_t n = 0;
  MPM_WIRE_TRY(r.count(n, (4 + 1) + 8));                         // a name and a value each
  if (static_cast<std::uint32_t>(n) > max_items) return WireError::kTooManyExtras;
  for (std::int32_t i = 0; i < n; ++i) MPM_WIRE_TRY(r.skip_string(max_string));
  MPM_WIRE_TRY(need(r.skip(static_cast<std::size_t>(n) * 8)));  // parameter_values
  MPM_WIRE_TRY(need(r.skip(8)));                                 // holdout_improvement
  MPM_WIRE_TRY(r.skip_string(max_string * 4));                   // text
  return r.left() == 0 ? WireError::kNone : WireError::kTrailingBytes;
}

#undef MPM_WIRE_TRY

}  // namespace mpm::transport
