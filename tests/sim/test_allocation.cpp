// ClosedLoop::step() (plant, DMC with its QP, noise, setpoints) allocates
// nothing once set up: global operator new is counted while it runs.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "sim/scenarios.hpp"

// The replacement pair below is malloc/free on both sides; GCC cannot see
// that through inlining and warns of a mismatch that is not there.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"

namespace {
std::atomic<long> g_allocations{0};
}

void* operator new(std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace mpm::sim {
namespace {

long allocations_during_steps(const char* name, int steps, std::size_t* constrained) {
  const Scenario& s = *find_scenario(name);
  ClosedLoop loop(default_plant(s).model, s.loop, 1);
  const long before = g_allocations.load();
  for (int k = 0; k < steps; ++k) loop.step();
  const long during = g_allocations.load() - before;
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
  const long before = g_allocations.load();
  auto* v = new std::vector<double>(100);
  delete v;
  EXPECT_GE(g_allocations.load() - before, 2);
}

}  // namespace
}  // namespace mpm::sim
