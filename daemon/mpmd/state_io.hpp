// The two visitors of a checkpoint: StateWriter appends every member a
// `visit_state(v)` hands it to a byte buffer, StateReader reads them back into
// an object built with the same plant and settings. Binary, in the machine's
// byte order (the file header records it, checkpoint.hpp).
//
// What a member may be: an arithmetic value or bool, an enum, a dense Eigen
// object, a std::vector of those or of objects with their own visit_state,
// a std::optional of either, or an object with visit_state. Sizes are
// written with the data and checked on reading against the sizes setup gave
// the object: a checkpoint never resizes anything, so a file of another
// plant, setting or program version is refused, not trusted. The reader
// stops at the first mismatch (ok() false, error() says where); the object
// is then partly overwritten and must be rebuilt by the caller.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include <Eigen/Dense>

namespace mpm::state {

template <class T>
struct is_vector : std::false_type {};
template <class T, class A>
struct is_vector<std::vector<T, A>> : std::true_type {};
template <class T>
struct is_optional : std::false_type {};
template <class T>
struct is_optional<std::optional<T>> : std::true_type {};
template <class T>
constexpr bool is_eigen_dense = std::is_base_of_v<Eigen::PlainObjectBase<T>, T>;
template <class T>
constexpr bool is_plain = std::is_arithmetic_v<T> || std::is_enum_v<T>;

class StateWriter {
 public:
  explicit StateWriter(std::vector<unsigned char>& out) : out_(out) {}

  template <class T>
  void operator()(T& x) {
    if constexpr (is_plain<T>) {
      bytes(&x, sizeof x);
    } else if constexpr (is_eigen_dense<T>) {
      static_assert(is_plain<typename T::Scalar>, "Eigen objects of plain scalars only");
      size(static_cast<std::uint64_t>(x.rows()));
      size(static_cast<std::uint64_t>(x.cols()));
      bytes(x.data(), sizeof(typename T::Scalar) * static_cast<std::size_t>(x.size()));
    } else if constexpr (is_vector<T>::value) {
      size(x.size());
      if constexpr (is_plain<typename T::value_type>) {
        static_assert(!std::is_same_v<typename T::value_type, bool>, "std::vector<bool> has no data()");
        bytes(x.data(), sizeof(typename T::value_type) * x.size());
      } else {
        for (auto& e : x) (*this)(e);
      }
    } else if constexpr (is_optional<T>::value) {
      bool present = x.has_value();
      (*this)(present);
      if (present) (*this)(*x);
    } else {
      x.visit_state(*this);
    }
  }

 private:
  void size(std::uint64_t n) { bytes(&n, sizeof n); }
  void bytes(const void* p, std::size_t n) {
    const auto* b = static_cast<const unsigned char*>(p);
    out_.insert(out_.end(), b, b + n);
  }
  std::vector<unsigned char>& out_;
};

class StateReader {
 public:
  StateReader(const unsigned char* data, std::size_t size) : data_(data), size_(size) {}

  bool ok() const noexcept { return error_.empty(); }
  const std::string& error() const noexcept { return error_; }
  // Every byte read, and no error.
  bool finished() const noexcept { return ok() && pos_ == size_; }
  std::size_t position() const noexcept { return pos_; }

  template <class T>
  void operator()(T& x) {
    if (!ok()) return;
    if constexpr (std::is_same_v<T, bool>) {
      unsigned char b = 2;
      bytes(&b, 1);
      if (ok() && b > 1) fail("a bool that is neither 0 nor 1");
      if (ok()) x = b == 1;
    } else if constexpr (is_plain<T>) {
      bytes(&x, sizeof x);
    } else if constexpr (is_eigen_dense<T>) {
      if (!expect_size(static_cast<std::uint64_t>(x.rows()), "matrix rows") ||
          !expect_size(static_cast<std::uint64_t>(x.cols()), "matrix columns")) {
        return;
      }
      bytes(x.data(), sizeof(typename T::Scalar) * static_cast<std::size_t>(x.size()));
    } else if constexpr (is_vector<T>::value) {
      if (!expect_size(x.size(), "vector length")) return;
      if constexpr (is_plain<typename T::value_type>) {
        bytes(x.data(), sizeof(typename T::value_type) * x.size());
      } else {
        for (auto& e : x) (*this)(e);
      }
    } else if constexpr (is_optional<T>::value) {
      bool present = false;
      (*this)(present);
      if (!ok()) return;
      if (present != x.has_value()) {
        fail(present ? "a part this setup does not have" : "a part this setup has is missing");
        return;
      }
      if (present) (*this)(*x);
    } else {
      x.visit_state(*this);
    }
  }

 private:
  void fail(const std::string& what) {
    if (ok()) error_ = what + " at byte " + std::to_string(pos_) + " of the state";
  }
  bool expect_size(std::uint64_t want, const char* what) {
    std::uint64_t n = 0;
    bytes(&n, sizeof n);
    if (ok() && n != want) fail(std::string(what) + " " + std::to_string(n) + " where the setup has " + std::to_string(want));
    return ok();
  }
  void bytes(void* p, std::size_t n) {
    if (!ok()) return;
    if (n > size_ - pos_) {
      fail("the state ends early (" + std::to_string(n) + " bytes wanted, " + std::to_string(size_ - pos_) +
           " left)");
      return;
    }
    if (n != 0) std::memcpy(p, data_ + pos_, n);
    pos_ += n;
  }
  const unsigned char* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
  std::string error_;
};

}  // namespace mpm::state
