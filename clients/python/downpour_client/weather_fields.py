"""The weather's fields, as server/sim/weather.hpp defines them.

Written by `build/downpour-scenes --weather`; do not edit (a test compares it with the
definition). interpolation: linear; angle (a + remainder(b - a, 360) * f); round (linear,
to the nearest whole number).
"""

FIELDS = (
    {"name": "rain_rate_mm_h", "unit": "mm/h", "min": 0.0, "max": 500.0, "default": 0.0,
     "interpolation": "linear", "integer": False,
     "meaning": "rain rate at the ground"},
    {"name": "wind_speed_mps", "unit": "m/s", "min": 0.0, "max": 100.0, "default": 0.0,
     "interpolation": "linear", "integer": False,
     "meaning": "wind speed"},
    {"name": "wind_direction_deg", "unit": "deg", "min": -360.0, "max": 360.0, "default": 0.0,
     "interpolation": "angle", "integer": False,
     "meaning": "direction the wind blows towards, world yaw"},
    {"name": "fog_density", "unit": "", "min": 0.0, "max": 1.0, "default": 0.0,
     "interpolation": "linear", "integer": False,
     "meaning": "0 = clear air"},
    {"name": "cloudiness", "unit": "", "min": 0.0, "max": 1.0, "default": 0.2,
     "interpolation": "linear", "integer": False,
     "meaning": "0 = clear sky, 1 = overcast"},
    {"name": "sun_altitude_deg", "unit": "deg", "min": -90.0, "max": 90.0, "default": 40.0,
     "interpolation": "linear", "integer": False,
     "meaning": "the sun's height over the horizon"},
    {"name": "sun_azimuth_deg", "unit": "deg", "min": -360.0, "max": 360.0, "default": 135.0,
     "interpolation": "angle", "integer": False,
     "meaning": "world yaw of the sun"},
    {"name": "rain_streak_count", "unit": "", "min": 0.0, "max": 80000.0, "default": 0.0,
     "interpolation": "round", "integer": True,
     "meaning": "drops around the car, drawn as streaks; 0 = from the rain rate (Marshall-Palmer)"},
    {"name": "rain_angle_deg", "unit": "deg", "min": -70.0, "max": 70.0, "default": 0.0,
     "interpolation": "linear", "integer": False,
     "meaning": "fall angle from vertical"},
)
