// The allocation counter behind `allocations_per_update` counts what a hot
// path could allocate (operator new, and Eigen's malloc where malloc is
// counted), so its 0 means something; and the monitor update really is 0.
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include <Eigen/Dense>

#include "support/alloc_counter.hpp"
#include "bench/workload.hpp"

namespace mpm::bench {
namespace {

using test::AllocationScope;
using test::counts_malloc;

TEST(AllocationScope, CountsOperatorNew) {
  AllocationScope scope;
  auto p = std::make_unique<std::vector<double>>(100);
  EXPECT_GE(scope.count(), 2);  // the vector object and its buffer
}

TEST(AllocationScope, CountsEigenStorageExactlyWhenMallocIsCounted) {
  AllocationScope scope;
  Eigen::VectorXd v = Eigen::VectorXd::Ones(1000);
  EXPECT_EQ(v.sum(), 1000.0);
  // Sanitizer builds leave malloc to the sanitizer: then Eigen is invisible,
  // as the figure's note says.
  if (counts_malloc()) {
    EXPECT_GE(scope.count(), 1);
  } else {
    EXPECT_EQ(scope.count(), 0);
  }
}

TEST(AllocationScope, CountsNothingWithoutAllocation) {
  std::vector<double> v(100, 1.0);
  AllocationScope scope;
  double s = 0.0;
  for (double x : v) s += x;
  EXPECT_EQ(s, 100.0);
  EXPECT_EQ(scope.count(), 0);
}

TEST(AllocationScope, MonitorUpdateAllocatesNothing) {
  const Workload w = make_workload(3, 2, 500);
  auto monitor = make_monitor(3, 2);
  std::size_t k = warm_up(*monitor, w, 0);
  AllocationScope scope;
  for (int i = 0; i < 200; ++i, ++k) monitor->update(w.u_at(k), w.residual_at(k));
  EXPECT_EQ(scope.count(), 0);
  EXPECT_EQ(monitor->counters().used, 201u);
}

}  // namespace
}  // namespace mpm::bench
