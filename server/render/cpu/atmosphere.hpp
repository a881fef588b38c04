// Sky and light from the weather: sun position and colour, sky colours, ambient light and fog.
// More rain and cloud make the scene darker and greyer, never brighter (seed 004, section 5).
#pragma once

#include <glm/vec3.hpp>

#include "server/sim/types.hpp"

namespace downpour::render {

struct Atmosphere {
  glm::vec3 sun_direction{0.0f, 0.0f, 1.0f};  // world, unit, towards the sun
  glm::vec3 sun_radiance{1.0f};               // direct light reaching the ground
  glm::vec3 sky_zenith{0.3f, 0.5f, 0.9f};
  glm::vec3 sky_horizon{0.7f, 0.8f, 0.95f};
  // The clear part of that gradient (before the clouds' grey is mixed in), which the scattered
  // sky's table replaces (sky_table.hpp); and the sun's altitude it is computed for (degrees).
  glm::vec3 clear_zenith{0.2f, 0.42f, 0.85f};
  glm::vec3 clear_horizon{0.68f, 0.8f, 0.95f};
  float sun_altitude_deg = 90.0f;
  glm::vec3 ambient{0.3f};  // light from the whole sky on an upward surface
  glm::vec3 fog_colour{0.7f};
  float fog_density = 0.0f;  // extinction per metre
  float overcast = 0.0f;     // 0 clear .. 1 fully grey
  float wetness = 0.0f;      // 0 dry .. 1 soaked, a stand-in until the road water grid
  // The camera's exposure for lamps: the radiance a white surface shows per lux on it. By day
  // the sun's 100,000 lux give it 1.4, and lamps barely show; at night the camera opens up some
  // 3,500 times, so that 10 lux of a low beam 10 m ahead shows a lit road.
  float lux_exposure = 1.4e-5f;
};

Atmosphere atmosphere_from(const sim::Weather& weather);
// The meteorological visibility (m) through this air: 2% contrast left (Koschmieder).
double visibility_m(const Atmosphere& atmosphere);

}  // namespace downpour::render
