// The step thread's allocations (issue 31's audit): once a drive has settled in, a tick of the
// simulation allocates almost nothing. Counted by replacing the global operator new for this
// program (it forwards to malloc; it counts only while a test arms it, on every thread).
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <new>

#include <gtest/gtest.h>

#include "server/sim/scenario.hpp"
#include "server/sim/simulation.hpp"

namespace {
std::atomic<bool> g_counting{false};
std::atomic<long> g_allocations{0};

void* counted_malloc(std::size_t size) noexcept {
  if (g_counting.load(std::memory_order_relaxed))
    g_allocations.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(size ? size : 1);
}
void* counted_or_throw(std::size_t size) {
  if (void* p = counted_malloc(size)) return p;
  throw std::bad_alloc();
}
}  // namespace

// The whole family, so that what one form allocates another frees (the sanitizers check).
void* operator new(std::size_t size) { return counted_or_throw(size); }
void* operator new[](std::size_t size) { return counted_or_throw(size); }
void* operator new(std::size_t size, const std::nothrow_t&) noexcept {
  return counted_malloc(size);
}
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept {
  return counted_malloc(size);
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }

namespace downpour::sim {
namespace {

// The loaded heavy-rain drive (the benchmark's): the windshield's water, the rain in the air, the
// road's water and the spray, at 30 ticks a second. After 5 s the pools have grown; then a second
// of ticks, counted. (Before the audit: 412 a tick, the road water's window moves nearly all of
// them.)
TEST(StepAllocationsTest, ASettledDriveAllocatesLittleATick) {
  const Scenario scenario = highway_heavy_rain();
  Simulation simulation(scenario.seed, scenario.at(0.0));
  const double dt = 1.0 / 30.0;
  const auto tick = [&] {
    simulation.apply(scenario.at(simulation.state().sim_time_s + dt));
    simulation.advance(dt);
  };
  for (int i = 0; i < 150; ++i) tick();
  constexpr int kTicks = 30;
  g_allocations = 0;
  g_counting = true;
  for (int i = 0; i < kTicks; ++i) tick();
  g_counting = false;
  const double per_tick = static_cast<double>(g_allocations.load()) / kTicks;
  std::printf("%.1f allocations a tick\n", per_tick);
  EXPECT_LT(per_tick, 60.0);
}

}  // namespace
}  // namespace downpour::sim
