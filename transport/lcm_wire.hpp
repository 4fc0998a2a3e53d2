// Our own reading of LCM's encoded bytes, so that the generated decoders
// never see untrusted input.
//
// Why: lcm-gen's decoders (LCM 1.3.1) resize every array to the length the
// datagram claims before they look at how many bytes the datagram has: one
// 60-byte sample_t with n_u = 2^31 - 1 made mpmd zero-fill 16 GB, and a
// string length of 0 or below is assign(p, -1). Here every length is checked
// against the bytes that remain AND against the limits (the plant's
// dimensions, string and extra caps) before anything is written, the way
// Cyclone's CDR reader checks lengths before it allocates.
//
// Layout (lcm-gen, all big endian): an 8-byte type fingerprint, then the
// fields in order; int32 array lengths precede their arrays; a string is an
// int32 length that counts its terminating NUL, then the bytes and the NUL;
// a boolean is one byte; nested structs carry no fingerprint.
//
// decode_lcm_sample writes into a reused msg::Sample by assigning into the
// storage it already has: once the first valid sample has sized it, decoding
// does not allocate, and what it can ever allocate is bounded by the limits.
#pragma once

#include <cstddef>
#include <cstdint>

#include "transport/messages.hpp"
#include "settings/transport_settings.hpp"

namespace mpm::transport {

enum class WireError : std::uint8_t {
  kNone,
  kTruncated,        // a field or array runs past the end of the bytes
  kFingerprint,      // not the type this channel carries
  kBadLength,        // a negative length, or a string without its NUL
  kStringTooLong,    // longer than SampleLimits::max_string
  kWrongInputs,      // n_u differs from the plant's inputs (or above max_channels)
  kWrongOutputs,     // n_y differs from the plant's outputs (or above max_channels)
  kWrongSimOutputs,  // n_sim_y neither 0 nor n_y
  kTooManyExtras,    // n_extra above SampleLimits::max_extra
  kTrailingBytes,    // bytes left after the last field
};

// A short phrase for logs ("n_u differs from the plant's inputs").
const char* describe(WireError error) noexcept;

// Decodes an encoded mpm_lcm.sample_t (fingerprint included). On an error
// `out` holds a partly decoded sample that must not be used; its storage
// stays within the limits either way.
WireError decode_lcm_sample(const void* data, std::size_t size, const SampleLimits& limits, msg::Sample& out);

// Walk an encoded alarm_t / status_t and check every length against the bytes
// that remain (strings at most `max_string` bytes, at most `max_items`
// channels and loops), allocating nothing. After kNone the generated decoder
// is safe on these bytes.
WireError check_lcm_alarm(const void* data, std::size_t size, std::uint32_t max_string) noexcept;
WireError check_lcm_status(const void* data, std::size_t size, std::uint32_t max_string,
                           std::uint32_t max_items) noexcept;
WireError check_lcm_diagnosis(const void* data, std::size_t size, std::uint32_t max_string,
                              std::uint32_t max_items) noexcept;

}  // namespace mpm::transport
