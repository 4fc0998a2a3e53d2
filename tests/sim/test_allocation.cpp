// ClosedLoop::step() (plant, DMC with its QP, noise, setpoints) allocates
// nothing once set up: operator new and malloc (support/alloc_counter.hpp)
// are counted while it runs.
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "sim/scenarios.hpp"
#include "support/alloc_counter.hpp"

namespace mpm::sim {
namespace {

long allocations_during_steps(const char* name, int steps, std::size_t* constrained) {
  const Scenario& s = *find_scenario(name);
  ClosedLoop loop(default_plant(s).model, s.loop, 1);
  long during = 0;
  {
    test::AllocationScope scope;
    for (int k = 0; k < steps; ++k) loop.step();
    during = static_cast<long>(scope.count());
  }
  *constrained = loop.controller().constrained_samples();
  return during;
}

TEST(Allocation, StepAllocatesNothing) {
  for (const char* name : {"wood-berry-saturation-u1", "wood-berry-feed-flow", "quad-tank-sensor-level1",
                           "quad-tank-g33-zero", "quad-tank-g32-integrator"}) {
    std::size_t constrained = 0;
    EXPECT_EQ(allocations_during_steps(name, 500, &constrained), 0) << name;
    if (std::string(name) == "quad-tank-g32-integrator") {
      EXPECT_GT(constrained, 100u);  // the QP ran
    }
  }
}

TEST(Allocation, TheCounterSeesAllocations) {
  test::AllocationScope scope;
  auto v = std::make_unique<std::vector<double>>(100);
  EXPECT_GE(scope.count(), 2);  // the vector object and its buffer
}

}  // namespace
}  // namespace mpm::sim
