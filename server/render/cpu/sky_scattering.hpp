// The clear sky's colour by the sun's place: single scattering of sunlight by the air's molecules
// (Rayleigh) and its haze (Mie, Henyey-Greenstein phase) in a spherical atmosphere, integrated
// along each view ray from the ground, with the sunlight's own extinction on its way to each point
// (and the Earth's shadow after sunset). No GL: a table the sky's shaders look up (sky_table.hpp).
#pragma once

#include <vector>

#include <glm/vec3.hpp>

#include "server/render/cpu/shader_interface.hpp"

namespace downpour::render {

struct SkyScatteringConfig {
  double earth_radius_m = 6360e3;
  double atmosphere_radius_m = 6420e3;
  glm::dvec3 rayleigh_per_m{5.8e-6, 13.5e-6, 33.1e-6};  // scattering at sea level, by channel
  double rayleigh_height_m = 7994.0;                    // its density's scale height
  double mie_per_m = 8e-6;  // the haze's scattering at sea level (clear air; 21e-6 is hazy)
  double mie_albedo = 0.9;  // scattering over extinction
  double mie_height_m = 1200.0;
  double mie_g = 0.5;  // forward scattering (broad: the sun's own glow is the shaders')
  // Ozone's absorption (Chappuis band: red and green, not blue), in a layer 10-40 km up: what
  // keeps the twilight sky blue overhead.
  glm::dvec3 ozone_per_m{0.65e-6, 1.881e-6, 0.085e-6};
  int view_samples = 16;
  int sun_samples = 6;
};

// The table's layout (its size kSkyTableWidth x kSkyTableHeight, shader_interface.hpp): columns
// by the view's azimuth from the sun's (u = (1 - cos) / 2: 0 towards the sun), rows by its
// elevation (v = sqrt(sin elevation): the horizon at 0, the zenith at 1).

// The sky's radiance (sunlight of 1 in each channel above the air) over the table's texels, rows
// from the horizon up, for a sun at this altitude (degrees; below 0 after sunset).
std::vector<glm::vec3> clear_sky_table(double sun_altitude_deg,
                                       const SkyScatteringConfig& config = {});

// One direction's radiance (the table's own computation): the view's elevation and its azimuth
// from the sun's, radians.
glm::dvec3 clear_sky_radiance(double sun_altitude_deg, double view_elevation_rad,
                              double azimuth_from_sun_rad, const SkyScatteringConfig& config = {});

}  // namespace downpour::render
