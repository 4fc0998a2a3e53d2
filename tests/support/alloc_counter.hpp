// Counts heap allocations made in this process while a scope is open, to show
// that a real-time path (the monitor's update, the receive path) allocates
// nothing after setup: the tests' zero-allocation checks and the bench's
// allocations_per_update both use it.
//
// Using it (linking mpm_test_support's alloc_counter.o) replaces the global
// operator new (every new in the program) and, on glibc without sanitizers,
// interposes malloc/calloc/realloc and the aligned allocations (Eigen's
// dynamic storage uses malloc, not new: counting only new would let an
// Eigen temporary pass). Both forward to the normal allocator; outside a
// counting scope they only test one atomic counter. Never in the product.
#pragma once

#include <cstdint>

namespace mpm::test {

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

}  // namespace mpm::test
