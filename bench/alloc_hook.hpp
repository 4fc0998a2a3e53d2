// Counts heap allocations made in this process while a scope is open, to show
// that the monitor's per-sample path allocates nothing after setup.
//
// Linking mpm_bench_lib replaces the global operator new (every new in the
// program) and, on glibc without sanitizers, interposes malloc/calloc/realloc
// (Eigen's dynamic storage uses malloc, not new). Both forward to the normal
// allocator; outside a counting scope they only test one atomic flag.
#pragma once

#include <cstdint>

namespace mpm::bench {

class AllocationScope {
 public:
  AllocationScope() noexcept;
  ~AllocationScope();
  AllocationScope(const AllocationScope&) = delete;
  AllocationScope& operator=(const AllocationScope&) = delete;
  std::int64_t count() const noexcept;  // allocations since the scope opened
};

// True when malloc itself is counted (not only operator new).
bool counts_malloc() noexcept;

}  // namespace mpm::bench
