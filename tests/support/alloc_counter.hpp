// Counts heap allocations made through global operator new / malloc-backed
// new in this test binary, so a test can assert a code path allocates nothing.
// Include in exactly one translation unit of a test executable.
#pragma once

#include <atomic>
#include <cstdlib>
#include <new>

// GCC sees malloc in operator new and free in operator delete after inlining
// and warns about a mismatch that is not one: they are a matching pair here.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"

namespace mpm::test {
inline std::atomic<long> g_allocations{0};
inline std::atomic<bool> g_counting{false};

// Counts allocations made while alive.
class AllocationScope {
 public:
  AllocationScope() { g_allocations = 0; g_counting = true; }
  ~AllocationScope() { g_counting = false; }
  long count() const { return g_allocations.load(); }
};
}  // namespace mpm::test

void* operator new(std::size_t n) {
  if (mpm::test::g_counting) ++mpm::test::g_allocations;
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) {
  if (mpm::test::g_counting) ++mpm::test::g_allocations;
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* operator new(std::size_t n, std::align_val_t a) {
  if (mpm::test::g_counting) ++mpm::test::g_allocations;
  if (void* p = std::aligned_alloc(static_cast<std::size_t>(a), (n + static_cast<std::size_t>(a) - 1) / static_cast<std::size_t>(a) * static_cast<std::size_t>(a))) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
