// The lamps of the vehicles and along the road (issue: light and relief): what a vehicle's lights
// are when the simulator leaves them automatic, when a flashing lamp is lit, and where the track's
// street lights stand. Plain data and pure functions; the renderer turns them into light.
#pragma once

#include <optional>
#include <vector>

#include <glm/vec3.hpp>

#include "server/sim/road_network.hpp"
#include "server/sim/types.hpp"

namespace downpour::sim {

struct LightsConfig {
  // Automatic headlights (low beam) below this sun, from this rain or this fog.
  double auto_sun_below_deg = 10.0;
  double auto_rain_from_mm_h = 1.0;
  double auto_fog_from = 0.1;
  // Automatic brake lights while the vehicle slows by this much (m/s^2, along its heading), and
  // while it stands (under 0.5 m/s) after braking.
  double auto_brake_from_mps2 = 1.5;
  double standing_below_mps = 0.5;
  // Indicators and hazard lights: flashes per second, lit half of each (ECE R48: 90 +- 30 a
  // minute).
  double indicator_hz = 1.5;
  // Street lights: one about every spacing_m along each road, on each side in turn, the pole set
  // back from the pavement's edge, the lamp at the end of an arm over the road; lit below this
  // sun, or under a sky this overcast with the sun below 25 degrees.
  double street_light_spacing_m = 25.0;
  double street_light_setback_m = 1.5;  // the pole, beyond the paved edge
  double street_light_height_m = 9.0;   // the lamp over the road surface
  double street_light_arm_m = 2.0;      // the lamp, towards the road from the pole
  double street_lights_sun_below_deg = 4.0;
  double street_lights_overcast_from = 0.9;
};

// Whether automatic headlights are on in this weather.
bool automatic_headlights_on(const Weather& weather, const LightsConfig& config = {});

// The lights a vehicle shows: the simulator's, with the automatic parts filled in (see the
// contract's VehicleState.lights); `braking` is whether it slows (VehicleMotion).
VehicleLights resolve_lights(const std::optional<VehicleLights>& given, const Weather& weather,
                             bool braking, const LightsConfig& config = {});

// Whether a flashing lamp (indicator, hazard) is lit at this time.
bool indicator_lit(double sim_time_s, const LightsConfig& config = {});

// Whether a vehicle slows, from its velocity at two updates dt_s apart: for automatic brake
// lights. Keeps braking while it stands after braking.
// Also how far it has rolled, for its wheels' turn: forward speed integrated over the updates.
struct VehicleMotion {
  glm::dvec3 velocity_mps{0.0};
  double time_s = 0.0;
  bool known = false;
  bool braking = false;
  double forward_mps = 0.0;  // along its heading at the last update
  double rolled_m = 0.0;     // at time_s, from its first update
  // Takes the vehicle's state at time_s (sim time).
  void observe(const VehicleState& state, double time_s, const LightsConfig& config = {});
  // How far it has rolled by a later time, on at its last speed.
  double rolled_at(double now_s) const { return rolled_m + forward_mps * (now_s - time_s); }
};

struct StreetLight {
  glm::dvec3 lamp_m{0.0};  // world: the lamp
  glm::dvec3 foot_m{0.0};  // world: the pole's foot
  int road = 0;            // the road it stands beside (road_network.hpp)
  double s = 0.0;          // along it
  int side = 1;            // 1 left of the direction of travel, -1 right
};
// The roads' street lights (none in junctions), in order along each road.
std::vector<StreetLight> street_lights(const RoadNetwork& roads, const LightsConfig& config = {});
std::vector<StreetLight> street_lights(const Track& track, const LightsConfig& config = {});
bool street_lights_on(const Weather& weather, const LightsConfig& config = {});

}  // namespace downpour::sim
