#include "server/sim/simulation.hpp"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "server/sim/scenario.hpp"

namespace downpour::sim {
namespace {

Update full_update(double t) {
  Update u;
  u.client_time_s = t;
  VehicleState v;
  v.position_m = {1.0, 2.0, 3.0};
  v.rotation = {10.0, 2.0, -1.0};
  v.velocity_mps = {25.0, 0.0, 0.0};
  u.vehicle = v;
  u.wipers = WiperState{WiperMode::kLow, 4.0, {}};
  Weather w;
  w.rain_rate_mm_h = 12.0;
  u.weather = w;
  u.traffic = std::vector<TrafficVehicle>{TrafficVehicle{3, {}, {4.5, 1.8, 1.5}}};
  return u;
}

TEST(SimulationTest, ThirtyFramesOfAThirtiethMakeOneSecond) {
  Simulation sim(1, {});
  for (int i = 0; i < 30; ++i) sim.advance(1.0 / 30.0);
  EXPECT_NEAR(sim.state().sim_time_s, 1.0, 1e-9);
  EXPECT_EQ(sim.state().sub_steps, 240u);
}

TEST(SimulationTest, SimTimeIsAWholeNumberOfSubSteps) {
  Simulation sim(1, {});
  sim.advance(0.01);  // 2.4 sub-steps
  EXPECT_EQ(sim.state().sub_steps, 2u);
  EXPECT_NEAR(sim.state().sim_time_s, 2.0 / 240.0, 1e-15);
  sim.advance(0.0);
  EXPECT_EQ(sim.state().sub_steps, 2u);
}

TEST(SimulationTest, SmallStepsAccumulateWithoutLosingTime) {
  Simulation sim(1, {});
  const double sub_step = SimulationConfig{}.sub_step_s;
  double total = 0.0;
  for (int i = 1; i <= 10000; ++i) {
    sim.advance(0.001);
    total += 0.001;
    // Behind the requested time by less than one sub-step, never ahead of it.
    ASSERT_LE(sim.state().sim_time_s, total + 1e-9) << "after " << i << " calls";
    ASSERT_GT(sim.state().sim_time_s, total - sub_step - 1e-9) << "after " << i << " calls";
  }
  EXPECT_EQ(sim.state().sub_steps, 2400u);
  EXPECT_NEAR(sim.state().sim_time_s, 10.0, 1e-9);
}

TEST(SimulationTest, UnevenStepsMatchOneBigStep) {
  Simulation a(1, {});
  Simulation b(1, {});
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> dt(0.0, 0.05);
  double total = 0.0;
  for (int i = 0; i < 1000; ++i) {
    const double d = dt(rng);
    a.advance(d);
    total += d;
  }
  b.advance(total);
  EXPECT_EQ(a.state().sub_steps, b.state().sub_steps);
  EXPECT_EQ(a.state().sub_steps, static_cast<std::uint64_t>(std::floor(total * 240.0)));
}

TEST(SimulationTest, InputsAfterAStepAreItsStateButTheWater) {
  const Scenario scenario = highway_heavy_rain();
  Simulation sim(scenario.seed, scenario.at(3.0));
  for (const double dt : {1.0 / 30.0, 1.0 / 60.0, 0.0101, 0.25, 1.0 / 240.0}) {
    const SceneState before = sim.inputs_after(dt);
    sim.advance(dt);
    EXPECT_EQ(before.sim_time_s, sim.state().sim_time_s) << "dt " << dt;
    EXPECT_EQ(before.sub_steps, sim.state().sub_steps);
    EXPECT_EQ(before.vehicle.position_m, sim.state().vehicle.position_m);
    EXPECT_EQ(before.weather.rain_rate_mm_h, sim.state().weather.rain_rate_mm_h);
    EXPECT_TRUE(before.windshield.metaballs.empty());
  }
}

TEST(SimulationTest, EachRoadStepPublishesANewImageOfTheRoadsWater) {
  const Scenario scenario = highway_heavy_rain();
  Simulation sim(scenario.seed, scenario.at(3.0));
  ASSERT_NE(sim.state().road_water, nullptr);  // (dry, before the first step)
  sim.advance(1.0);
  const auto image = sim.state().road_water;
  ASSERT_NE(image, nullptr);
  EXPECT_EQ(image->cells, sim.road().cells());
  EXPECT_EQ(image->levels, sim.road().levels());
  EXPECT_EQ(image->origins[0], sim.road().origin(0));
  EXPECT_GT(image->mean_water_mm, 0.0f);
  // What is drawn while the next step runs: the image the last one left.
  EXPECT_EQ(sim.inputs_after(1.0 / 30.0).road_water, image);
  sim.advance(1.0 / 240.0);  // no road step: the same image
  EXPECT_EQ(sim.state().road_water, image);
  sim.advance(1.0 / 30.0);
  EXPECT_NE(sim.state().road_water, image);
}

TEST(SimulationTest, ConfiguredSubStep) {
  SimulationConfig config;
  config.sub_step_s = 0.01;
  Simulation sim(1, {}, config);
  sim.advance(0.1);
  EXPECT_EQ(sim.state().sub_steps, 10u);
  EXPECT_NEAR(sim.state().sim_time_s, 0.1, 1e-12);
}

TEST(SimulationTest, InitialUpdateIsApplied) {
  Simulation sim(1, full_update(5.0));
  EXPECT_EQ(sim.state().client_time_s, 5.0);
  EXPECT_EQ(sim.state().vehicle.position_m, glm::dvec3(1.0, 2.0, 3.0));
  EXPECT_EQ(sim.state().wipers.mode, WiperMode::kLow);
  EXPECT_EQ(sim.state().weather.rain_rate_mm_h, 12.0);
  ASSERT_EQ(sim.state().traffic.size(), 1u);
  EXPECT_EQ(sim.state().sim_time_s, 0.0);
}

TEST(SimulationTest, PartialUpdateKeepsTheAbsentParts) {
  Simulation sim(1, full_update(1.0));
  Update only_weather;
  only_weather.client_time_s = 2.0;
  Weather w;
  w.rain_rate_mm_h = 50.0;
  only_weather.weather = w;
  sim.apply(only_weather);
  EXPECT_EQ(sim.state().client_time_s, 2.0);
  EXPECT_EQ(sim.state().weather.rain_rate_mm_h, 50.0);
  EXPECT_EQ(sim.state().vehicle.position_m, glm::dvec3(1.0, 2.0, 3.0));
  EXPECT_EQ(sim.state().vehicle.velocity_mps, glm::dvec3(25.0, 0.0, 0.0));
  EXPECT_EQ(sim.state().wipers.mode, WiperMode::kLow);
  ASSERT_EQ(sim.state().traffic.size(), 1u);
  EXPECT_EQ(sim.state().traffic[0].id, 3u);

  // A present but empty traffic list replaces the list.
  Update clear_traffic;
  clear_traffic.traffic = std::vector<TrafficVehicle>{};
  sim.apply(clear_traffic);
  EXPECT_TRUE(sim.state().traffic.empty());
  EXPECT_EQ(sim.state().weather.rain_rate_mm_h, 50.0);
}

TEST(SimulationTest, SameSeedAndInputsGiveTheSameState) {
  Simulation a(99, full_update(0.0));
  Simulation b(99, full_update(0.0));
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> dt(0.0, 0.1);
  for (int i = 0; i < 200; ++i) {
    const double d = dt(rng);
    Update u = full_update(i * 0.1);
    u.vehicle->position_m.x = i;
    if (i % 3 == 0) u.weather.reset();
    a.apply(u);
    b.apply(u);
    a.advance(d);
    b.advance(d);
    const SceneState& sa = a.state();
    const SceneState& sb = b.state();
    ASSERT_EQ(sa.sim_time_s, sb.sim_time_s);
    ASSERT_EQ(sa.sub_steps, sb.sub_steps);
    ASSERT_EQ(sa.client_time_s, sb.client_time_s);
    ASSERT_EQ(sa.vehicle.position_m, sb.vehicle.position_m);
    ASSERT_EQ(sa.weather.rain_rate_mm_h, sb.weather.rain_rate_mm_h);
    ASSERT_EQ(sa.wipers.mode, sb.wipers.mode);
    ASSERT_EQ(sa.traffic.size(), sb.traffic.size());
  }
}

}  // namespace
}  // namespace downpour::sim
