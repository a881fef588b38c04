// The step thread's allocations (issue 31's audit): once a drive has settled in, a tick of the
// simulation allocates almost nothing (counted through the global operator new, on every thread:
// tests/support/allocation_counter.hpp).
#include <cstdio>

#include <gtest/gtest.h>

#include "server/sim/scenario.hpp"
#include "server/sim/simulation.hpp"
#include "server/sim/worker_thread.hpp"
#include "tests/support/allocation_counter.hpp"

namespace downpour::sim {
namespace {

// The loaded heavy-rain drive (the benchmark's): the windshield's water, the rain in the air, the
// road's water and the spray, at 30 ticks a second, stepped as the server steps it (the world
// outside the glass on a helper thread). After 5 s the pools have grown; then a second of ticks,
// counted. (Before the audit: 412 a tick, the road water's window moves nearly all of
// them.)
TEST(StepAllocationsTest, ASettledDriveAllocatesLittleATick) {
  const Scenario scenario = highway_heavy_rain();
  Simulation simulation(scenario.seed, scenario.at(0.0));
  WorkerThread helper("dp-world");
  const double dt = 1.0 / 30.0;
  const auto tick = [&] {
    simulation.apply(scenario.at(simulation.state().sim_time_s + dt));
    simulation.advance(dt, &helper);
  };
  for (int i = 0; i < 150; ++i) tick();
  constexpr int kTicks = 30;
  testing::start_counting_allocations();
  for (int i = 0; i < kTicks; ++i) tick();
  const double per_tick = static_cast<double>(testing::stop_counting_allocations()) / kTicks;
  std::printf("%.1f allocations a tick\n", per_tick);
  EXPECT_LT(per_tick, 60.0);
}

}  // namespace
}  // namespace downpour::sim
