#include "server/render/cpu/atmosphere.hpp"

#include <algorithm>
#include <cmath>

#include <glm/common.hpp>
#include <glm/exponential.hpp>
#include <glm/trigonometric.hpp>

#include "server/sim/rain_field.hpp"

namespace downpour::render {

Atmosphere atmosphere_from(const sim::Weather& w) {
  Atmosphere a;
  const float alt = glm::radians(static_cast<float>(w.sun_altitude_deg));
  const float az = glm::radians(static_cast<float>(w.sun_azimuth_deg));
  a.sun_direction =
      glm::vec3(std::cos(alt) * std::cos(az), std::cos(alt) * std::sin(az), std::sin(alt));

  const float rain = static_cast<float>(w.rain_rate_mm_h);
  // Rain needs cloud: even light rain greys the sky; heavy rain darkens it further.
  const float rain_cloud = 1.0f - std::exp(-rain / 3.0f);
  a.overcast = std::clamp(std::max(static_cast<float>(w.cloudiness), rain_cloud), 0.0f, 1.0f);
  const float rain_darkening = 1.0f - 0.55f * (1.0f - std::exp(-rain / 20.0f));
  // Daylight fades through civil twilight (sun 6 degrees below the horizon).
  const float day = glm::smoothstep(-6.0f, 12.0f, static_cast<float>(w.sun_altitude_deg));
  const float night = 0.02f;
  const float level = (night + (1.0f - night) * day) * (1.0f - 0.35f * a.overcast) * rain_darkening;

  const glm::vec3 clear_zenith(0.20f, 0.42f, 0.85f);
  const glm::vec3 clear_horizon(0.68f, 0.80f, 0.95f);
  const glm::vec3 grey_zenith(0.52f, 0.55f, 0.58f);
  const glm::vec3 grey_horizon(0.66f, 0.68f, 0.70f);
  // A low sun warms the horizon.
  const float alt_deg = static_cast<float>(w.sun_altitude_deg);
  const float low_sun = glm::smoothstep(25.0f, 0.0f, alt_deg) * day;
  const glm::vec3 warm(1.0f, 0.72f, 0.5f);
  // Below 25 degrees the sky dims faster than the sun's beam (a clear sky gives a horizontal
  // surface about as much light as a sun 5 degrees high gives one facing it, at noon a fifth), and
  // the camera opens up to make up for part of the loss: the relief's grazing light and long
  // shadows show at dusk.
  const float sky_dim = 1.0f - 0.7f * low_sun;
  const float exposure = 1.0f + 0.9f * low_sun;
  const float sky_level = level * sky_dim * exposure;
  a.clear_zenith = clear_zenith * sky_level;
  a.clear_horizon = glm::mix(clear_horizon, clear_horizon * warm, low_sun) * sky_level;
  a.sky_zenith = glm::mix(a.clear_zenith, grey_zenith * sky_level, a.overcast);
  a.sky_horizon = glm::mix(a.clear_horizon, grey_horizon * sky_level, a.overcast);
  a.sun_altitude_deg = alt_deg;

  // The beam through the air: reddened along its path, by the air mass (Kasten and Young) beyond
  // a 25-degree sun's; its disc sets over the horizon's last degree and a half.
  const float above = glm::smoothstep(-0.8f, 0.8f, alt_deg);
  const float airmass = [&] {
    const float deg = std::max(alt_deg, 0.0f);
    return 1.0f / (std::sin(glm::radians(deg)) + 0.50572f * std::pow(deg + 6.07995f, -1.6364f));
  }();
  const float airmass_25 = 2.35f;
  const glm::vec3 extinction(0.03f, 0.07f, 0.15f);  // per air mass, relative: red passes
  const glm::vec3 reddening = glm::exp(-extinction * std::max(airmass - airmass_25, 0.0f));
  const float direct = (1.0f - 0.9f * a.overcast) * rain_darkening;
  a.sun_radiance = glm::vec3(1.0f, 0.95f, 0.88f) * reddening * 1.4f * direct * above * exposure;
  a.ambient = glm::mix(a.sky_zenith, a.sky_horizon, 0.5f) * 0.9f;

  // Extinction: clear air sees kilometres; fog and rain bring the horizon in (the rain's from its
  // drop sizes, sim/rain_field.hpp: 2.5 km of visibility at 10 mm/h, 930 m at 50).
  a.fog_density = 0.00012f + static_cast<float>(w.fog_density) * 0.012f +
                  static_cast<float>(sim::rain_extinction_per_m(w.rain_rate_mm_h));
  a.fog_colour = a.sky_horizon;
  a.wetness = std::clamp(rain / 5.0f, 0.0f, 1.0f);
  // Between day and night the exposure follows the daylight geometrically (log-linearly).
  const float night_exposure = 0.05f, day_exposure = 1.4e-5f;
  a.lux_exposure = night_exposure * std::pow(day_exposure / night_exposure, day);
  return a;
}

double visibility_m(const Atmosphere& atmosphere) {
  return sim::visibility_m(atmosphere.fog_density);
}

}  // namespace downpour::render
