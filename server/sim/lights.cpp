#include "server/sim/lights.hpp"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

namespace downpour::sim {

bool automatic_headlights_on(const Weather& w, const LightsConfig& c) {
  return w.sun_altitude_deg < c.auto_sun_below_deg || w.rain_rate_mm_h >= c.auto_rain_from_mm_h ||
         w.fog_density >= c.auto_fog_from;
}

VehicleLights resolve_lights(const std::optional<VehicleLights>& given, const Weather& weather,
                             bool braking, const LightsConfig& config) {
  VehicleLights out = given.value_or(VehicleLights{});
  if (out.headlights == Headlights::kAuto) {
    out.headlights = automatic_headlights_on(weather, config) ? Headlights::kLow : Headlights::kOff;
  }
  if (!given) out.brake = braking;
  return out;
}

bool indicator_lit(double sim_time_s, const LightsConfig& config) {
  const double phase = sim_time_s * config.indicator_hz;
  return phase - std::floor(phase) < 0.5;
}

void VehicleMotion::observe(const VehicleState& state, double now_s, const LightsConfig& config) {
  const double yaw = state.rotation.yaw_deg * M_PI / 180.0;
  const glm::dvec3 heading(std::cos(yaw), std::sin(yaw), 0.0);
  const double speed = glm::length(state.velocity_mps);
  const double dt = now_s - time_s;
  if (known && dt > 1e-6) {
    const double accel = glm::dot(state.velocity_mps - velocity_mps, heading) / dt;
    const bool forward = glm::dot(velocity_mps, heading) >= 0.0;
    const bool slowing =
        forward ? accel <= -config.auto_brake_from_mps2 : accel >= config.auto_brake_from_mps2;
    braking = slowing || (braking && speed < config.standing_below_mps);
  } else if (!known) {
    braking = false;
  }
  if (!known || dt > 1e-6) {
    const double forward = glm::dot(state.velocity_mps, heading);
    if (known) rolled_m += 0.5 * (forward_mps + forward) * dt;
    forward_mps = forward;
    velocity_mps = state.velocity_mps;
    time_s = now_s;
  }
  known = true;
}

std::vector<StreetLight> street_lights(const RoadNetwork& roads, const LightsConfig& c) {
  std::vector<StreetLight> out;
  for (int road = 0; road < roads.road_count(); ++road) {
    if (roads.connecting(road)) continue;
    const double length = roads.road_length(road);
    const bool loops = roads.road_loops(road);
    // Around a loop from its start; along a road, centred on it (none on one shorter than the
    // spacing); none whose pole would stand on a road.
    const int n = static_cast<int>(std::floor(length / c.street_light_spacing_m));
    for (int i = 0; i < n; ++i) {
      const double s = length * (loops ? i : i + 0.5) / n;
      const TrackFrame f = roads.frame(road, s);
      const PavedSpan span = roads.paved(road, s);
      const int side = i % 2 == 0 ? 1 : -1;
      const double edge = side > 0 ? span.left : span.right;
      const double pole_lat = edge + side * c.street_light_setback_m;
      const double lamp_lat = pole_lat - side * c.street_light_arm_m;
      StreetLight l;
      l.road = road;
      l.s = s;
      l.side = side;
      const glm::dvec2 foot = glm::dvec2(f.position) + f.left * pole_lat;
      const glm::dvec2 lamp = glm::dvec2(f.position) + f.left * lamp_lat;
      // Not on another road (beside a junction, or a road running alongside).
      const RoadPlace under = roads.project(foot, 30.0);
      if (under.road != road && roads.paved(under.road, under.s).contains(under.t)) continue;
      l.foot_m = {foot.x, foot.y, roads.surface_height({road, s, edge})};
      l.lamp_m = {lamp.x, lamp.y,
                  roads.surface_height({road, s, std::clamp(lamp_lat, span.right, span.left)}) +
                      c.street_light_height_m};
      out.push_back(l);
    }
  }
  return out;
}

std::vector<StreetLight> street_lights(const Track& track, const LightsConfig& config) {
  return street_lights(TrackRoads(track), config);
}

bool street_lights_on(const Weather& w, const LightsConfig& c) {
  return w.sun_altitude_deg < c.street_lights_sun_below_deg ||
         (w.cloudiness >= c.street_lights_overcast_from && w.sun_altitude_deg < 25.0);
}

}  // namespace downpour::sim
