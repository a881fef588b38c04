// The vehicles' lamps and the track's street lights: automatic headlights by the weather, brake
// lights from slowing between updates, the simulator's own state kept, flashing at 1.5 Hz, and
// street lights beside the road at their spacing.
#include "server/sim/lights.hpp"

#include <cmath>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include "server/sim/simulation.hpp"

namespace downpour::sim {
namespace {

Weather clear_noon() {
  Weather w;
  w.sun_altitude_deg = 50.0;
  w.cloudiness = 0.2;
  return w;
}

TEST(LightsTest, AutomaticHeadlightsComeOnAtDuskInRainAndInFog) {
  Weather w = clear_noon();
  EXPECT_EQ(resolve_lights(std::nullopt, w, false).headlights, Headlights::kOff);
  w.sun_altitude_deg = 6.0;
  EXPECT_EQ(resolve_lights(std::nullopt, w, false).headlights, Headlights::kLow) << "low sun";
  w = clear_noon();
  w.rain_rate_mm_h = 2.0;
  EXPECT_EQ(resolve_lights(std::nullopt, w, false).headlights, Headlights::kLow) << "rain";
  w = clear_noon();
  w.fog_density = 0.2;
  EXPECT_EQ(resolve_lights(std::nullopt, w, false).headlights, Headlights::kLow) << "fog";
}

TEST(LightsTest, TheSimulatorsStateIsKeptAndOnlyItsAutoPartFilledIn) {
  Weather night = clear_noon();
  night.sun_altitude_deg = -20.0;
  VehicleLights given;
  given.headlights = Headlights::kHigh;
  given.left_indicator = true;
  VehicleLights out = resolve_lights(given, night, true);
  EXPECT_EQ(out.headlights, Headlights::kHigh);
  EXPECT_TRUE(out.left_indicator);
  EXPECT_FALSE(out.brake) << "a given state's brake lights are the simulator's";
  given.headlights = Headlights::kOff;
  EXPECT_EQ(resolve_lights(given, night, false).headlights, Headlights::kOff);
  given.headlights = Headlights::kAuto;
  EXPECT_EQ(resolve_lights(given, night, false).headlights, Headlights::kLow);
  EXPECT_TRUE(resolve_lights(std::nullopt, night, true).brake) << "absent: from slowing";
}

TEST(LightsTest, IndicatorsFlashAtOneAndAHalfHertz) {
  int lit = 0, changes = 0;
  bool last = indicator_lit(0.0);
  for (int i = 1; i <= 2000; ++i) {  // 2 s in 1 ms steps
    const bool now = indicator_lit(i * 1e-3);
    lit += now;
    changes += now != last;
    last = now;
  }
  EXPECT_NEAR(lit / 2000.0, 0.5, 0.01);
  EXPECT_EQ(changes, 6) << "3 flashes in 2 s: on and off 6 times";
}

// A traffic car in the simulation, updated at 10 Hz: cruising, braking at 4 m/s^2 to a stop, then
// standing; and the ego car likewise.
TEST(LightsTest, BrakeLightsFollowSlowingBetweenUpdatesAndStayOnWhileStanding) {
  Update initial;
  initial.weather = clear_noon();
  initial.vehicle = VehicleState{};
  Simulation sim(1, initial);
  auto at_speed = [](double v) {
    VehicleState s;
    s.velocity_mps = {v, 0.0, 0.0};
    return s;
  };
  auto update = [&](double v) {
    Update u;
    u.vehicle = at_speed(v);
    u.traffic = std::vector<TrafficVehicle>{{7, at_speed(v), {4.5, 1.8, 1.5}}};
    sim.apply(u);
    sim.advance(0.1);
  };
  update(20.0);
  update(20.0);
  EXPECT_FALSE(sim.state().traffic_lights.at(0).brake) << "cruising";
  EXPECT_FALSE(sim.state().ego_lights.brake);
  update(19.6);
  EXPECT_TRUE(sim.state().traffic_lights.at(0).brake) << "slowing at 4 m/s^2";
  EXPECT_TRUE(sim.state().ego_lights.brake);
  update(19.55);
  EXPECT_FALSE(sim.state().traffic_lights.at(0).brake) << "easing off, 0.5 m/s^2";
  update(0.3);
  update(0.0);
  update(0.0);
  EXPECT_TRUE(sim.state().traffic_lights.at(0).brake) << "standing after braking";
  update(2.0);
  EXPECT_FALSE(sim.state().traffic_lights.at(0).brake) << "pulling away";
  EXPECT_EQ(sim.inputs_after(0.1).traffic_lights.size(), 1u) << "carried to the frame's inputs";
}

TEST(LightsTest, StreetLightsStandBesideTheRoadAtTheirSpacingAndLightAtDusk) {
  const Track& track = Track::built_in();
  const LightsConfig config;
  const std::vector<StreetLight> lights = street_lights(track, config);
  ASSERT_GT(lights.size(), 10u);
  EXPECT_NEAR(track.length() / static_cast<double>(lights.size()), config.street_light_spacing_m,
              config.street_light_spacing_m * 0.05);
  for (const StreetLight& l : lights) {
    const Track::Projection foot = track.project({l.foot_m.x, l.foot_m.y}, 50.0);
    EXPECT_NEAR(std::abs(foot.lateral), track.paved_half_width() + config.street_light_setback_m,
                0.05);
    const Track::Projection lamp = track.project({l.lamp_m.x, l.lamp_m.y}, 50.0);
    EXPECT_LT(std::abs(lamp.lateral), std::abs(foot.lateral)) << "the arm reaches over the road";
    EXPECT_NEAR(l.lamp_m.z - track.surface_height(lamp.s, lamp.lateral),
                config.street_light_height_m, 0.1);
  }
  Weather w = clear_noon();
  EXPECT_FALSE(street_lights_on(w));
  w.sun_altitude_deg = 2.0;
  EXPECT_TRUE(street_lights_on(w));
  w = clear_noon();
  w.sun_altitude_deg = 15.0;
  w.cloudiness = 0.95;
  EXPECT_TRUE(street_lights_on(w)) << "a dark overcast afternoon";
}

// How far a vehicle has rolled, for its wheels: its forward speed over the updates (the mean of
// each two), on at the last speed between them; backwards counts back.
TEST(VehicleMotionTest, RolledDistanceFollowsTheForwardSpeed) {
  VehicleMotion m;
  VehicleState s;
  s.rotation.yaw_deg = 90.0;  // heading +y
  s.velocity_mps = {0.0, 10.0, 0.0};
  m.observe(s, 1.0);
  EXPECT_DOUBLE_EQ(m.rolled_at(1.0), 0.0);
  EXPECT_NEAR(m.rolled_at(1.5), 5.0, 1e-9);
  s.velocity_mps = {0.0, 20.0, 0.0};
  m.observe(s, 2.0);
  EXPECT_NEAR(m.rolled_at(2.0), 15.0, 1e-9);  // the mean of 10 and 20 over a second
  s.velocity_mps = {0.0, -4.0, 0.0};          // reversing
  m.observe(s, 3.0);
  EXPECT_NEAR(m.rolled_at(3.0), 23.0, 1e-9);
  EXPECT_NEAR(m.rolled_at(4.0), 19.0, 1e-9);
}

}  // namespace
}  // namespace downpour::sim
