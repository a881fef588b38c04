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
    velocity_mps = state.velocity_mps;
    time_s = now_s;
  }
  known = true;
}

std::vector<StreetLight> street_lights(const Track& track, const LightsConfig& c) {
  std::vector<StreetLight> out;
  const double half = track.paved_half_width();
  const int n =
      std::max(1, static_cast<int>(std::floor(track.length() / c.street_light_spacing_m)));
  for (int i = 0; i < n; ++i) {
    const double s = track.length() * i / n;
    const TrackFrame f = track.at(s);
    const int side = i % 2 == 0 ? 1 : -1;
    const double pole_lat = side * (half + c.street_light_setback_m);
    const double lamp_lat = pole_lat - side * c.street_light_arm_m;
    StreetLight l;
    l.s = s;
    l.side = side;
    const glm::dvec2 foot = glm::dvec2(f.position) + f.left * pole_lat;
    const glm::dvec2 lamp = glm::dvec2(f.position) + f.left * lamp_lat;
    const double edge_z = track.surface_height(s, side * half);
    l.foot_m = {foot.x, foot.y, edge_z};
    l.lamp_m = {
        lamp.x, lamp.y,
        track.surface_height(s, std::clamp(lamp_lat, -half, half)) + c.street_light_height_m};
    out.push_back(l);
  }
  return out;
}

bool street_lights_on(const Weather& w, const LightsConfig& c) {
  return w.sun_altitude_deg < c.street_lights_sun_below_deg ||
         (w.cloudiness >= c.street_lights_overcast_from && w.sun_altitude_deg < 25.0);
}

}  // namespace downpour::sim
