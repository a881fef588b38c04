"""CARLA's values in Downpour's contract, as plain numbers (no carla or protobuf import here).

Frames. CARLA (Unreal Engine) is left-handed: x forward, y right, z up, in metres (wheel
positions in its physics control are in centimetres). Downpour's world is right-handed: x, y
left, z up. A CARLA point maps to (x, -y, z).

Rotations. CARLA's rotator (pitch, yaw, roll), degrees: pitch positive nose up, yaw positive
turning right seen from above, roll positive right side down. Downpour's rotation is
Rz(yaw) Ry(pitch) Rx(roll) about its own axes: yaw positive turning left, pitch positive nose
down, roll positive right side down (the left side up). So yaw -> -yaw, pitch -> -pitch, roll ->
roll (the tests check it on the axes' vectors).

Pose reference. CARLA places an actor at its root (for vehicles near the middle of the body, on
the ground); Downpour's pose is the point on the ground under the rear axle's centre. The offset
between the two, in the vehicle's frame, comes from the rear wheels once (rear_axle_local) and
moves with the actor after that (pose_from_carla).

Weather. CARLA's 0-100 sliders in Downpour's units:
- precipitation p -> rain 50 (e^(3 p / 100) - 1) / (e^3 - 1) mm/h: 0.9 mm/h at 10 (drizzle), 3.8
  at 30 (CARLA's SoftRain), 13 at 60 (MidRain), 50 at 100 (HardRain, a downpour);
- cloudiness and fog_density: / 100, linear;
- wind_intensity -> 0.2 m/s per unit (100: 20 m/s, a gale); CARLA gives no direction: it blows
  along the world's +x unless the bridge is told otherwise;
- sun_altitude_angle as it is; sun_azimuth_angle mirrored like a yaw.

Lamps. CARLA's VehicleLightState bit flags: low and high beam, brake, the blinkers, reverse.
"""

import math

# carla.VehicleLightState's flags.
LIGHT_POSITION = 0x1
LIGHT_LOW_BEAM = 0x2
LIGHT_HIGH_BEAM = 0x4
LIGHT_BRAKE = 0x8
LIGHT_RIGHT_BLINKER = 0x10
LIGHT_LEFT_BLINKER = 0x20
LIGHT_REVERSE = 0x40

RAIN_AT_FULL_MM_H = 50.0
RAIN_CURVE = 3.0
WIND_MPS_PER_UNIT = 0.2


def location_to_world(x, y, z):
    """A CARLA location (metres) in Downpour's world frame."""
    return (x, -y, z)


def rotation_to_world(pitch, yaw, roll):
    """A CARLA rotator (degrees) as Downpour's (yaw, pitch, roll), degrees."""
    return (-yaw, -pitch, roll)


def carla_axes(pitch, yaw, roll):
    """CARLA's forward, right and up unit vectors of a rotator, in CARLA's frame (as its
    Rotation.get_forward_vector, get_right_vector and get_up_vector give them)."""
    p, y, r = (math.radians(v) for v in (pitch, yaw, roll))
    sp, cp, sy, cy, sr, cr = math.sin(p), math.cos(p), math.sin(y), math.cos(y), math.sin(r), math.cos(r)
    forward = (cp * cy, cp * sy, sp)
    right = (sr * sp * cy - cr * sy, sr * sp * sy + cr * cy, -sr * cp)
    up = (-(cr * sp * cy + sr * sy), cy * sr - cr * sp * sy, cr * cp)
    return forward, right, up


def rear_axle_local(location, rotation, rear_wheels_cm, wheel_radius_m):
    """The ground point under the rear axle's centre in the vehicle's CARLA frame (forward, right,
    up; metres), from the actor's location and rotator and its two rear wheels' world positions
    in centimetres (carla.WheelPhysicsControl.position) with their radius: measured once, it
    moves with the actor."""
    centre = [(a + b) / 200.0 for a, b in zip(rear_wheels_cm[0], rear_wheels_cm[1])]
    forward, right, up = carla_axes(*rotation)
    d = [c - l for c, l in zip(centre, location)]
    dot = lambda u, v: sum(a * b for a, b in zip(u, v))
    return (dot(d, forward), dot(d, right), dot(d, up) - wheel_radius_m)


def pose_from_carla(location, rotation, axle_local):
    """Downpour's pose (position, (yaw, pitch, roll)) of a CARLA actor at `location` (metres) with
    the rotator `rotation` (pitch, yaw, roll degrees), its rear axle's ground point at
    `axle_local` in its frame (rear_axle_local)."""
    forward, right, up = carla_axes(*rotation)
    point = [l + axle_local[0] * f + axle_local[1] * r + axle_local[2] * u
             for l, f, r, u in zip(location, forward, right, up)]
    return location_to_world(*point), rotation_to_world(*rotation)


def velocity_to_world(vx, vy, vz):
    return (vx, -vy, vz)


def size_from_extent(ex, ey, ez):
    """A bounding box's half extents (carla.BoundingBox.extent) as length, width, height."""
    return (2.0 * ex, 2.0 * ey, 2.0 * ez)


def rain_mm_h(precipitation):
    p = min(max(precipitation, 0.0), 100.0) / 100.0
    return RAIN_AT_FULL_MM_H * math.expm1(RAIN_CURVE * p) / math.expm1(RAIN_CURVE)


def weather_from_carla(cloudiness, precipitation, wind_intensity, sun_azimuth_angle,
                       sun_altitude_angle, fog_density, wind_direction_deg=0.0):
    """Downpour's Weather fields from CARLA's WeatherParameters values."""
    clamp01 = lambda v: min(max(v / 100.0, 0.0), 1.0)
    azimuth = -sun_azimuth_angle
    azimuth = (azimuth + 180.0) % 360.0 - 180.0
    return {
        "rain_rate_mm_h": rain_mm_h(precipitation),
        "cloudiness": clamp01(cloudiness),
        "fog_density": clamp01(fog_density),
        "wind_speed_mps": WIND_MPS_PER_UNIT * min(max(wind_intensity, 0.0), 100.0),
        "wind_direction_deg": wind_direction_deg,
        "sun_altitude_deg": min(max(sun_altitude_angle, -90.0), 90.0),
        "sun_azimuth_deg": azimuth,
    }


def lights_from_carla(state):
    """Downpour's VehicleLights fields from carla.VehicleLightState flags."""
    if state & LIGHT_HIGH_BEAM:
        headlights = "HIGH"
    elif state & LIGHT_LOW_BEAM:
        headlights = "LOW"
    else:
        headlights = "OFF"
    return {
        "headlights": headlights,
        "brake": bool(state & LIGHT_BRAKE),
        "left_indicator": bool(state & LIGHT_LEFT_BLINKER),
        "right_indicator": bool(state & LIGHT_RIGHT_BLINKER),
        "reverse": bool(state & LIGHT_REVERSE),
    }


def vehicle_class(base_type, number_of_wheels=4):
    """A vehicle's class from its blueprint's base_type attribute (car, truck, van, bus,
    motorcycle, bicycle) and wheel count, as Downpour's traffic classes name them."""
    kind = (base_type or "").lower()
    if kind in ("truck", "bus"):
        return kind
    if kind in ("motorcycle", "bicycle") or number_of_wheels == 2:
        return "motorbike"
    return "car"


def camera_from_view(axle_local, position_m, rotation_deg):
    """Where a CARLA camera attached to the vehicle must sit to take a view's pictures: the view's
    camera pose (Downpour's vehicle frame from the rear axle's ground point: x forward, y left, z
    up; yaw left, pitch nose down, roll right down) as a location in the actor's CARLA frame
    (forward, right, up, metres) and a rotator (pitch up, yaw right, roll)."""
    x, y, z = position_m
    yaw, pitch, roll = rotation_deg
    location = (axle_local[0] + x, axle_local[1] - y, axle_local[2] + z)
    return location, (-pitch, -yaw, roll)


def horizontal_fov_deg(vertical_fov_deg, width, height):
    """CARLA's camera fov (horizontal) for a view's vertical fov at width x height."""
    half = math.radians(vertical_fov_deg) / 2.0
    return math.degrees(2.0 * math.atan(math.tan(half) * width / height))
