#include "transport/lcm_wire.hpp"

#include <cstring>
#include <string_view>
#include <type_traits>
#include <utility>

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
  bool u8(std::uint8_t& v) noexcept {
    if (left_ < 1) return false;
    v = p_[0];
    advance(1);
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

template <class T>
constexpr std::size_t scalar_bytes() noexcept {
  if constexpr (std::is_same_v<T, bool>) return 1;
  else if constexpr (std::is_same_v<T, std::string>) return 4 + 1;  // the empty string: length and NUL
  else return sizeof(T);
}

// The smallest encoding of a message of type M (every array empty, every
// string ""): what an array's length is checked against before it is read.
template <class M>
constexpr std::size_t min_bytes() noexcept {
  std::size_t n = 0;
  msg::for_each_field<M>([&](const auto& field) {
    using Field = std::remove_cvref_t<decltype(field)>;
    if constexpr (msg::is<Field>(msg::FieldKind::kScalar))
      n += scalar_bytes<std::remove_cvref_t<decltype(field.get(std::declval<M&>()))>>();
    else n += 4;  // an array's length
  });
  return n;
}

// What a walk may accept besides the bytes' own consistency.
struct Caps {
  std::uint32_t max_string;  // bytes of a string (4 x that for a `line`)
  std::uint32_t max_items;   // elements of an array of nested messages or of named values
  const SampleLimits* plant = nullptr;  // a sample's arrays of doubles are checked against it
  std::int32_t n_y = 0;      // the outputs read so far (sim_y has none or as many)
};

// A sample's u and y against the plant's dimensions, sim_y none or one per output.
WireError plant_dimension(Caps& caps, std::string_view field, std::int32_t n) noexcept {
  const SampleLimits& plant = *caps.plant;
  if (field == "u" && !dimension_ok(n, plant.n_u, plant.max_channels)) return WireError::kWrongInputs;
  if (field == "y") {
    if (!dimension_ok(n, plant.n_y, plant.max_channels)) return WireError::kWrongOutputs;
    caps.n_y = n;
  }
  if (field == "sim_y" && n != 0 && n != caps.n_y) return WireError::kWrongSimOutputs;
  return WireError::kNone;
}

template <class M, class Field>
WireError walk_field(Reader& r, Caps& caps, const Field& field, M* out);

// Walks the fields of an encoded M after its fingerprint, checking every
// length against the bytes that remain and against `caps` before anything
// is read. With `out`, decodes into it (assigning into the storage it has);
// without, allocates nothing.
template <class M>
WireError walk(Reader& r, Caps& caps, M* out) {
  WireError error = WireError::kNone;
  msg::for_each_field<M>([&](const auto& field) {
    if (error == WireError::kNone) error = walk_field<M>(r, caps, field, out);
  });
  return error;
}

template <class M, class Field>
WireError walk_field(Reader& r, Caps& caps, const Field& field, M* out) {
  if constexpr (msg::is<Field>(msg::FieldKind::kScalar)) {
    using T = std::remove_cvref_t<decltype(field.get(std::declval<M&>()))>;
    if constexpr (std::is_same_v<T, std::string>) {
      const char* chars = nullptr;
      std::size_t length = 0;
      MPM_WIRE_TRY(r.string(chars, length, field.names.line ? caps.max_string * 4 : caps.max_string));
      if (out != nullptr) field.get(*out).assign(chars, length);
    } else if (out == nullptr) {
      MPM_WIRE_TRY(need(r.skip(scalar_bytes<T>())));
    } else if constexpr (std::is_same_v<T, bool>) {
      std::uint8_t b = 0;
      MPM_WIRE_TRY(need(r.u8(b)));
      field.get(*out) = b != 0;
    } else if constexpr (std::is_same_v<T, double>) {
      MPM_WIRE_TRY(need(r.f64(field.get(*out))));
    } else if constexpr (std::is_same_v<T, std::int64_t>) {
      MPM_WIRE_TRY(need(r.i64(field.get(*out))));
    } else {
      MPM_WIRE_TRY(need(r.i32(field.get(*out))));
    }
  } else if constexpr (msg::is<Field>(msg::FieldKind::kArray)) {
    using Element = msg::ElementOf<M, Field>;
    std::int32_t n = 0;
    if constexpr (std::is_same_v<Element, double>) {
      MPM_WIRE_TRY(r.count(n, 8));
      if (caps.plant != nullptr) MPM_WIRE_TRY(plant_dimension(caps, field.names.name, n));
      // Assigned even when empty: a reused message must not keep the
      // previous one's values (LCM 1.3's decoder skips zero-length arrays).
      if (out != nullptr) MPM_WIRE_TRY(need(read_doubles(r, static_cast<std::size_t>(n), field.get(*out))));
      else MPM_WIRE_TRY(need(r.skip(static_cast<std::size_t>(n) * 8)));
    } else {
      MPM_WIRE_TRY(r.count(n, min_bytes<Element>()));
      if (static_cast<std::uint32_t>(n) > caps.max_items) return WireError::kTooManyExtras;
      if (out != nullptr) field.get(*out).resize(static_cast<std::size_t>(n));
      for (std::int32_t i = 0; i < n; ++i) {
        Element* item = out != nullptr ? &field.get(*out)[static_cast<std::size_t>(i)] : nullptr;
        MPM_WIRE_TRY(walk(r, caps, item));
      }
    }
  } else {  // named values: one length, the names, the values
    std::int32_t n = 0;
    MPM_WIRE_TRY(r.count(n, scalar_bytes<std::string>() + 8));
    if (static_cast<std::uint32_t>(n) > caps.max_items) return WireError::kTooManyExtras;
    const auto count = static_cast<std::size_t>(n);
    if (out != nullptr) field.names(*out).resize(count);
    for (std::size_t i = 0; i < count; ++i) {
      const char* chars = nullptr;
      std::size_t length = 0;
      MPM_WIRE_TRY(r.string(chars, length, caps.max_string));
      if (out != nullptr) field.names(*out)[i].assign(chars, length);
    }
    if (out != nullptr) MPM_WIRE_TRY(need(read_doubles(r, count, field.values(*out))));
    else MPM_WIRE_TRY(need(r.skip(count * 8)));
  }
  return WireError::kNone;
}

// An encoded M, fingerprint first, nothing after the last field.
template <class M>
WireError walk_message(const void* data, std::size_t size, std::int64_t hash, Caps caps, M* out) {
  Reader r(data, size);
  MPM_WIRE_TRY(fingerprint(r, hash));
  MPM_WIRE_TRY(walk(r, caps, out));
  return r.left() == 0 ? WireError::kNone : WireError::kTrailingBytes;
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
  return walk_message(data, size, mpm_lcm::sample_t::getHash(), Caps{limits.max_string, limits.max_extra, &limits},
                      &out);
}

WireError check_lcm_alarm(const void* data, std::size_t size, std::uint32_t max_string) noexcept {
  return walk_message<msg::Alarm>(data, size, mpm_lcm::alarm_t::getHash(), Caps{max_string, 0}, nullptr);
}

WireError check_lcm_status(const void* data, std::size_t size, std::uint32_t max_string,
                           std::uint32_t max_items) noexcept {
  return walk_message<msg::Status>(data, size, mpm_lcm::status_t::getHash(), Caps{max_string, max_items}, nullptr);
}

WireError check_lcm_diagnosis(const void* data, std::size_t size, std::uint32_t max_string,
                              std::uint32_t max_items) noexcept {
  return walk_message<msg::Diagnosis>(data, size, mpm_lcm::diagnosis_t::getHash(), Caps{max_string, max_items},
                                      nullptr);
}

#undef MPM_WIRE_TRY

}  // namespace mpm::transport
