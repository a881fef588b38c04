// The step's helper thread (Simulation::advance with a WorkerThread, as FrameScheduler runs it):
// the world outside the glass steps on it beside the glass's water, and a lockstep run must not
// see which. In the thread tests too (./downpour.sh tsan).
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include "server/sim/simulation.hpp"
#include "server/sim/worker_thread.hpp"
#include "tests/support/spray_drive.hpp"

namespace downpour::sim {
namespace {

// Every bit of what a tick leaves that the world outside the glass and the glass's water write,
// folded into one number (FNV-1a over the bytes).
std::uint64_t digest(const Simulation& sim) {
  std::uint64_t h = 1469598103934665603ull;
  auto add = [&](const void* data, std::size_t size) {
    const auto* bytes = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < size; ++i) h = (h ^ bytes[i]) * 1099511628211ull;
  };
  auto value = [&](const auto& v) { add(&v, sizeof v); };
  for (const auto& d : sim.water().drops()) {
    if (!d.alive) continue;
    value(d.pos);
    value(d.mass);
    value(d.moving);
    value(d.subs);
  }
  for (const auto& p : sim.water().particles()) {
    value(p.pos);
    value(p.mass);
  }
  const WaterLedger l = sim.water().ledger();
  value(l.arrived);
  value(l.wiped_off);
  for (const auto& p : sim.spray().particles()) {
    value(p.position_m);
    value(p.volume_m3);
  }
  const SceneState& s = sim.state();
  add(s.rain.drops.data(), s.rain.drops.size() * sizeof(s.rain.drops[0]));
  if (s.road_water)
    add(s.road_water->water_standing_mm.data(), s.road_water->water_standing_mm.size() * 4);
  add(s.windshield.metaballs.data(), s.windshield.metaballs.size() * sizeof(Metaball));
  value(s.windshield.glass_wet_fraction);
  value(s.ego_body_wet);
  return h;
}

// Behind a truck whose spray lands on the
// glass, every tick's state is the same bit for bit with the helper and without.
TEST(SimulationTest, AHelperThreadLeavesEveryTickTheSame) {
  testing::SprayDrive d;
  d.truck_gap_m = 14.0;
  d.seconds = 3.0;
  d.rain_mm_h = 8.0;
  std::vector<std::uint64_t> alone, helped;
  const Simulation a =
      testing::drive(d, [&](const Simulation& sim) { alone.push_back(digest(sim)); });
  WorkerThread helper("dp-world");
  d.helper = &helper;
  const Simulation b =
      testing::drive(d, [&](const Simulation& sim) { helped.push_back(digest(sim)); });
  ASSERT_EQ(alone.size(), helped.size());
  for (std::size_t i = 0; i < alone.size(); ++i) ASSERT_EQ(alone[i], helped[i]) << "tick " << i;
  // The drive is one that tests this: the truck's spray reached the glass.
  EXPECT_GT(a.spray().ledger().on_glass_m3, 0.0);
  EXPECT_GT(b.water().drop_count(), 0u);
}

// The hand-over at other rates: the glass's water every sub-step, every 3 and every 8, and steps
// of uneven length, some shorter than a sub-step (an advance with no sub-step in it), others
// several water steps long.
TEST(SimulationTest, AHelperThreadLeavesTheStateTheSameAtOtherRatesAndSteps) {
  for (const int water_every : {1, 3, 8}) {
    SCOPED_TRACE(water_every);
    SimulationConfig config;
    config.road.initial_m = 0.0008;
    config.windshield.sub_steps_per_water_step = water_every;
    Update start;
    double s = 400.0;
    constexpr double kSpeed = 25.0;
    start.vehicle = testing::on_track(s, kSpeed);
    Weather w;
    w.rain_rate_mm_h = 8.0;
    start.weather = w;
    Simulation alone(9, start, config), helped(9, start, config);
    WorkerThread helper("dp-world");
    const double steps[] = {1.0 / 30.0, 0.001, 0.05, 1.0 / 240.0, 0.003, 0.02};
    double t = 0.0;
    for (int i = 0; t < 1.5; ++i) {
      const double dt = steps[i % 6];
      t += dt;
      s += kSpeed * dt;
      Update u;
      u.client_time_s = t;
      u.vehicle = testing::on_track(s, kSpeed);
      u.traffic = std::vector<TrafficVehicle>{
          {1, testing::on_track(s + 14.0, kSpeed), testing::kTruckSize}};
      alone.apply(u);
      helped.apply(u);
      alone.advance(dt);
      helped.advance(dt, &helper);
      ASSERT_EQ(digest(alone), digest(helped)) << "step " << i << ", dt " << dt;
    }
    EXPECT_GT(alone.spray().ledger().on_glass_m3, 0.0);
  }
}

}  // namespace
}  // namespace downpour::sim
