"""SUMO's vehicle state in Downpour's contract, as plain numbers (no traci or protobuf import).

Frames. SUMO's network coordinates are metres, x east, y north, z up (right-handed, as
Downpour's world). A network made from OpenDRIVE by netconvert keeps the file's coordinates with
--offset.disable-normalization; otherwise netconvert shifts them by the net's netOffset
(<location netOffset="dx,dy">: SUMO = OpenDRIVE + offset), which the bridge takes back off.

Angles. SUMO's vehicle angle is a compass heading: degrees clockwise from north (+y). Downpour's
yaw is counter-clockwise from +x: yaw = 90 - angle. SUMO's slope is degrees, positive uphill;
Downpour's pitch is positive nose down: pitch = -slope.

Reference point. SUMO places a vehicle at the middle of its front bumper; Downpour's pose is the
ground under the rear axle's centre. The ego car's front bumper is 3.65 m ahead of its rear axle
at its default 4.6 m (the contract's VehicleState; the bridge gives the session the SUMO ego's size
and scales that); a traffic vehicle's shape is its class's, scaled to its length, so
its rear axle lies a fixed share of its length behind the front bumper (REAR_AXLE_FROM_FRONT).

Lamps. TraCI's vehicle signals are bits: 0 right blinker, 1 left blinker, 2 emergency (both), 3
brake light, 4 front (low beam), 5 fog, 6 high beam, 7 reversing. SUMO's car-following models set
the blinkers on lane changes and turns, and the brake light while braking; it sets no headlights,
so those stay automatic unless a bit says otherwise.
"""

import math

# The contract's VehicleClass numbers (proto/downpour/v1/downpour.proto).
CAR, TRUCK, BUS, MOTORBIKE = 1, 2, 3, 4

# SUMO's vehicle classes (vClass) as Downpour's shapes; others are cars.
SUMO_CLASSES = {
    "passenger": CAR, "private": CAR, "taxi": CAR, "evehicle": CAR, "emergency": CAR,
    "authority": CAR, "army": CAR, "vip": CAR, "custom1": CAR, "custom2": CAR,
    "delivery": CAR, "truck": TRUCK, "trailer": TRUCK, "bus": BUS, "coach": BUS,
    "motorcycle": MOTORBIKE, "moped": MOTORBIKE, "bicycle": MOTORBIKE,
}

# The share of a vehicle's length from its front bumper back to its rear axle, by class (the
# shapes in server/sim/vehicle_class.cpp: a 4.6 m car's rear axle is 0.95 m in front of its rear
# bumper, a 12 m truck's 3.0, a 12 m bus's 3.4, a 2.2 m motorbike's 0.45).
REAR_AXLE_FROM_FRONT = {
    CAR: (4.6 - 0.95) / 4.6,
    TRUCK: (12.0 - 3.0) / 12.0,
    BUS: (12.0 - 3.4) / 12.0,
    MOTORBIKE: (2.2 - 0.45) / 2.2,
}
EGO_FRONT_BUMPER_M = 3.65  # ahead of the ego car's rear axle, at its default length
EGO_LENGTH_M = 4.6  # (the bridge sends the SUMO ego's size as the session's, and scales this)
MAX_TRAFFIC = 64  # the server's limit on traffic vehicles in an update

SIGNAL_RIGHT, SIGNAL_LEFT, SIGNAL_EMERGENCY, SIGNAL_BRAKE = 1, 2, 4, 8
SIGNAL_FRONT, SIGNAL_FOG, SIGNAL_HIGH_BEAM, SIGNAL_REVERSE = 16, 32, 64, 128

# The contract's Headlights numbers.
HEADLIGHTS_AUTO, HEADLIGHTS_OFF, HEADLIGHTS_LOW, HEADLIGHTS_HIGH = 0, 1, 2, 3


def vehicle_class(sumo_class):
    return SUMO_CLASSES.get(sumo_class, CAR)


def yaw_deg(sumo_angle_deg):
    """SUMO's compass angle -> Downpour's yaw, in (-180, 180]."""
    yaw = 90.0 - sumo_angle_deg
    yaw = math.fmod(yaw + 180.0, 360.0)
    if yaw <= 0.0:
        yaw += 360.0
    return yaw - 180.0


def pose(front_xyz, sumo_angle_deg, slope_deg, speed_mps, front_to_rear_axle_m,
         net_offset=(0.0, 0.0)):
    """A vehicle's contract pose from SUMO's: (position under the rear axle, (yaw, pitch, roll)
    in degrees, world velocity), tuples."""
    yaw = yaw_deg(sumo_angle_deg)
    h, p = math.radians(yaw), math.radians(slope_deg)
    forward = (math.cos(h) * math.cos(p), math.sin(h) * math.cos(p), math.sin(p))
    x = front_xyz[0] - net_offset[0] - front_to_rear_axle_m * forward[0]
    y = front_xyz[1] - net_offset[1] - front_to_rear_axle_m * forward[1]
    z = front_xyz[2] - front_to_rear_axle_m * forward[2]
    velocity = tuple(speed_mps * f for f in forward)
    return (x, y, z), (yaw, -slope_deg, 0.0), velocity


def traffic_front_to_rear_axle_m(klass, length_m):
    return REAR_AXLE_FROM_FRONT.get(klass, REAR_AXLE_FROM_FRONT[CAR]) * length_m


def lights(signals):
    """TraCI's signal bits -> the contract's VehicleLights fields, a dict."""
    headlights = (HEADLIGHTS_HIGH if signals & SIGNAL_HIGH_BEAM
                  else HEADLIGHTS_LOW if signals & SIGNAL_FRONT else HEADLIGHTS_AUTO)
    emergency = bool(signals & SIGNAL_EMERGENCY)
    return {
        "headlights": headlights,
        "brake": bool(signals & SIGNAL_BRAKE),
        "left_indicator": emergency or bool(signals & SIGNAL_LEFT),
        "right_indicator": emergency or bool(signals & SIGNAL_RIGHT),
        "reverse": bool(signals & SIGNAL_REVERSE),
    }


def net_offset(net_xml_text):
    """The (dx, dy) of a SUMO network's <location netOffset="dx,dy">, (0, 0) if none."""
    start = net_xml_text.find("<location")
    if start < 0:
        return (0.0, 0.0)
    key = 'netOffset="'
    at = net_xml_text.find(key, start, net_xml_text.find(">", start))
    if at < 0:
        return (0.0, 0.0)
    value = net_xml_text[at + len(key):net_xml_text.find('"', at + len(key))]
    dx, dy = (float(v) for v in value.split(","))
    return (dx, dy)


class TrafficIds:
    """SUMO's vehicle ids (strings) as the contract's numbers, stable for a run: in the order
    first seen."""

    def __init__(self):
        self._ids = {}

    def __call__(self, sumo_id):
        if sumo_id not in self._ids:
            self._ids[sumo_id] = len(self._ids) + 1
        return self._ids[sumo_id]
