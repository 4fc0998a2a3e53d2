#include "support/alloc_counter.hpp"

#include <atomic>
#include <cerrno>
#include <cstddef>
#include <cstdlib>
#include <new>

// GCC pairs the malloc inside operator new with the free inside operator
// delete after inlining and warns of a mismatch that is not one.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"

#if defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || __has_feature(memory_sanitizer)
#define MPM_BENCH_SANITIZED 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define MPM_BENCH_SANITIZED 1
#endif
// Sanitizers intercept malloc themselves: there only operator new is counted.
#if defined(__GLIBC__) && !defined(MPM_BENCH_SANITIZED)
#define MPM_BENCH_COUNT_MALLOC 1
#endif

namespace {
std::atomic<std::int64_t> g_allocations{0};
std::atomic<int> g_open_scopes{0};

inline void note_allocation() noexcept {
  if (g_open_scopes.load(std::memory_order_relaxed) > 0) g_allocations.fetch_add(1, std::memory_order_relaxed);
}
}  // namespace

namespace mpm::test {

AllocationScope::AllocationScope() noexcept {
  g_allocations.store(0);
  g_open_scopes.fetch_add(1);
}
AllocationScope::~AllocationScope() { g_open_scopes.fetch_sub(1); }
std::int64_t AllocationScope::count() const noexcept { return g_allocations.load(); }

bool counts_malloc() noexcept {
#ifdef MPM_BENCH_COUNT_MALLOC
  return true;
#else
  return false;
#endif
}

}  // namespace mpm::test

#ifdef MPM_BENCH_COUNT_MALLOC
extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void __libc_free(void*);
void* __libc_memalign(std::size_t, std::size_t);

void* malloc(std::size_t n) {
  note_allocation();
  return __libc_malloc(n);
}
void* calloc(std::size_t count, std::size_t n) {
  note_allocation();
  return __libc_calloc(count, n);
}
void* realloc(void* p, std::size_t n) {
  note_allocation();
  return __libc_realloc(p, n);
}
void* memalign(std::size_t alignment, std::size_t n) {
  note_allocation();
  return __libc_memalign(alignment, n);
}
void* aligned_alloc(std::size_t alignment, std::size_t n) {
  note_allocation();
  return __libc_memalign(alignment, n);
}
int posix_memalign(void** out, std::size_t alignment, std::size_t n) {
  if (alignment % sizeof(void*) != 0 || (alignment & (alignment - 1)) != 0) return EINVAL;
  note_allocation();
  void* p = __libc_memalign(alignment, n);
  if (!p) return ENOMEM;
  *out = p;
  return 0;
}
void free(void* p) { __libc_free(p); }
}
// operator new goes through the counted malloc above: count it there only.
namespace {
inline void* plain_allocate(std::size_t n) { return __libc_malloc(n ? n : 1); }
}  // namespace
#else
namespace {
inline void* plain_allocate(std::size_t n) { return std::malloc(n ? n : 1); }
}  // namespace
#endif

void* operator new(std::size_t n) {
  note_allocation();
  if (void* p = plain_allocate(n)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) {
  note_allocation();
  if (void* p = plain_allocate(n)) return p;
  throw std::bad_alloc();
}
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  note_allocation();
  return plain_allocate(n);
}
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept {
  note_allocation();
  return plain_allocate(n);
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
