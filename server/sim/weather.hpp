// The weather: the one definition of its fields. Each field's name (the proto's, the scenario
// files'), C++ type, unit, the range the server accepts, the value a scenario file's keyframe
// takes when it leaves the field out (also the session's weather before any update), and how
// scenarios interpolate it between keyframes. Everything else follows this list:
// - the struct below and the table kWeatherFields;
// - rpc/validation.cpp's checks, and sim/scenario.cpp's reading, writing and interpolation;
// - clients/python/downpour_client/weather_fields.py (written by `downpour-scenes --weather`;
//   a test fails when it is stale), read by the Python scenario reader and the viewer;
// - the table in docs/contract.md (the same test checks it).
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <string_view>
#include <type_traits>

#include <glm/vec3.hpp>

namespace downpour::sim {

// How a scenario carries a field between two keyframes a and b at fraction u:
// kLinear a + (b - a) u; kAngle the shorter way round, a + remainder(b - a, 360) u (no wrapping
// of the result); kRound linear, rounded to the nearest whole number.
enum class Interpolation { kLinear, kAngle, kRound };

// X(name, type, unit, min, max, default, interpolation, meaning)
#define DOWNPOUR_WEATHER_FIELDS(X)                                                        \
  X(rain_rate_mm_h, double, "mm/h", 0.0, 500.0, 0.0, kLinear, "rain rate at the ground")  \
  X(wind_speed_mps, double, "m/s", 0.0, 100.0, 0.0, kLinear, "wind speed")                \
  X(wind_direction_deg, double, "deg", -360.0, 360.0, 0.0, kAngle,                        \
    "direction the wind blows towards, world yaw")                                        \
  X(fog_density, double, "", 0.0, 1.0, 0.0, kLinear, "0 = clear air")                     \
  X(cloudiness, double, "", 0.0, 1.0, 0.2, kLinear, "0 = clear sky, 1 = overcast")        \
  X(sun_altitude_deg, double, "deg", -90.0, 90.0, 40.0, kLinear,                          \
    "the sun's height over the horizon")                                                  \
  X(sun_azimuth_deg, double, "deg", -360.0, 360.0, 135.0, kAngle, "world yaw of the sun") \
  X(rain_streak_count, std::uint32_t, "", 0.0, 80000.0, 0.0, kRound,                      \
    "drops around the car, drawn as streaks; 0 = from the rain rate (Marshall-Palmer)")   \
  X(rain_angle_deg, double, "deg", -70.0, 70.0, 0.0, kLinear, "fall angle from vertical")

struct Weather {
#define DOWNPOUR_WEATHER_MEMBER(name, type, unit, min, max, fallback, interpolation, meaning) \
  type name = static_cast<type>(fallback);
  DOWNPOUR_WEATHER_FIELDS(DOWNPOUR_WEATHER_MEMBER)
#undef DOWNPOUR_WEATHER_MEMBER
};

struct WeatherField {
  std::string_view name, unit;
  double min, max, fallback;  // fallback: a keyframe's value when its file leaves it out
  Interpolation interpolation;
  std::string_view meaning;
  bool integer;  // a whole number (its type is unsigned)
  double (*get)(const Weather&);
  void (*set)(Weather&, double);  // integers are rounded
};

namespace weather_detail {
template <typename T>
T from_double(double v) {
  if constexpr (std::is_integral_v<T>) {
    return static_cast<T>(std::llround(v));
  } else {
    return static_cast<T>(v);
  }
}
}  // namespace weather_detail

inline constexpr std::array kWeatherFields = {
#define DOWNPOUR_WEATHER_ROW(name, type, unit, min, max, fallback, interpolation, meaning) \
  WeatherField{#name,                                                                      \
               unit,                                                                       \
               min,                                                                        \
               max,                                                                        \
               fallback,                                                                   \
               Interpolation::interpolation,                                               \
               meaning,                                                                    \
               std::is_integral_v<type>,                                                   \
               [](const Weather& w) { return static_cast<double>(w.name); },               \
               [](Weather& w, double v) { w.name = weather_detail::from_double<type>(v); }},
    DOWNPOUR_WEATHER_FIELDS(DOWNPOUR_WEATHER_ROW)
#undef DOWNPOUR_WEATHER_ROW
};

// The wind's velocity (m/s, world, z 0): wind_speed_mps towards wind_direction_deg.
inline glm::dvec3 wind_velocity(const Weather& w) {
  const double dir = w.wind_direction_deg * M_PI / 180.0;
  return {w.wind_speed_mps * std::cos(dir), w.wind_speed_mps * std::sin(dir), 0.0};
}

// From angle a towards b the shorter way round (degrees), at fraction u; the result is not
// wrapped. Scenarios carry the vehicle's rotation this way too.
inline double lerp_angle_deg(double a, double b, double u) {
  return a + std::remainder(b - a, 360.0) * u;
}

// One field's value between keyframes a and b at fraction u, as its interpolation says.
inline double interpolate(const WeatherField& f, double a, double b, double u) {
  switch (f.interpolation) {
    case Interpolation::kAngle:
      return lerp_angle_deg(a, b, u);
    case Interpolation::kRound:
      return std::round(a + (b - a) * u);
    case Interpolation::kLinear:
      break;
  }
  return a + (b - a) * u;
}

}  // namespace downpour::sim
