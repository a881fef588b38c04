"""Scenario files: a timeline of keyframes, interpolated into Update messages.

Each keyframe may carry any of three channels: vehicle, wipers, weather. A channel is interpolated
between the neighbouring keyframes that carry it: positions and velocities linearly, rotations
along the shortest arc, each weather field as its definition says (weather_fields.py), wipers held
from the last keyframe at or before t. Before a channel's first keyframe its first value holds,
after its last keyframe its last value. A weather field left out takes its definition's default;
a wiper interval left out is 4 s; other fields left out are 0, as in the proto. The server's own
reader (server/sim/scenario.cpp) gives the same updates: a test compares them sample by sample.
"""

import bisect
import json
import math

from downpour.v1 import downpour_pb2 as pb

from .messages import mode_value, rotation, to_view_spec, vec3, view_value, wiper_mode_value
from .weather_fields import FIELDS as WEATHER

WEATHER_FIELDS = tuple(field["name"] for field in WEATHER)
DEFAULT_INTERVAL_S = 4.0
VEHICLE_FIELDS = ("position_m", "rotation_deg", "velocity_mps")
WIPER_FIELDS = ("mode", "interval_s", "blade_angle_deg")
VIEW_FIELDS = ("view", "width", "height", "jpeg_quality", "fov_deg", "focus_distance_m",
               "aperture_mm", "exposure_s")
# The lens and shutter of a view, optional: left out, the proto field stays unset (the view's own).
LENS_RANGES = {"focus_distance_m": (0.05, 10000.0), "aperture_mm": (0.0, 50.0),
               "exposure_s": (0.0, 0.25)}
TOP_FIELDS = ("name", "description", "duration_s", "loop", "seed", "fps", "views", "keyframes")
MAX_VIEWS = 4


class Scenario:
    """A validated scenario. Scenario(data) takes the parsed JSON; Scenario.load(path) a file."""

    def __init__(self, data):
        _object(data, "scenario", TOP_FIELDS)
        self.name = _string(data, "name", "name")
        self.description = _string(data, "description", "description", default="")
        self.duration_s = _number(data, "duration_s", "duration_s", positive=True)
        self.loop = _boolean(data, "loop", "loop", default=False)
        self.seed = _integer(data, "seed", "seed", default=0, maximum=2**64 - 1)
        self.fps = _number(data, "fps", "fps", default=30.0, positive=True)
        self.views = _views(data)
        self._times = {"vehicle": [], "wipers": [], "weather": []}
        self._values = {"vehicle": [], "wipers": [], "weather": []}
        keyframes = _require(data, "keyframes", "keyframes")
        if not isinstance(keyframes, list) or not keyframes:
            raise ValueError("keyframes: must be a non-empty list")
        previous_t = None
        for index, keyframe in enumerate(keyframes):
            path = f"keyframes[{index}]"
            _object(keyframe, path, ("t", "vehicle", "wipers", "weather"))
            t = _number(keyframe, "t", f"{path}.t")
            if t < 0 or t > self.duration_s:
                raise ValueError(f"{path}.t: must be in [0, duration_s={self.duration_s:g}], "
                                 f"got {t:g}")
            if previous_t is not None and t <= previous_t:
                raise ValueError(f"{path}.t: keyframes must be sorted by t with no repeats, "
                                 f"got {t:g} after {previous_t:g}")
            previous_t = t
            for channel, parse in (("vehicle", _vehicle), ("wipers", _wipers),
                                   ("weather", _weather)):
                if channel in keyframe:
                    self._times[channel].append(t)
                    self._values[channel].append(parse(keyframe[channel], f"{path}.{channel}"))

    @classmethod
    def load(cls, path):
        with open(path, encoding="utf-8") as file:
            text = file.read()
        try:
            return cls(json.loads(text))
        except ValueError as error:
            raise ValueError(f"{path}: {error}") from None

    def has_channel(self, channel):
        return bool(self._times[channel])

    def local_time(self, t):
        """Scenario time for clock time t: wrapped modulo duration_s when the scenario loops."""
        return t % self.duration_s if self.loop else t

    def at(self, t):
        """The Update at time t; sim_time_s is t itself, the channels are those the file has."""
        local = self.local_time(t)
        update = pb.Update(sim_time_s=t)
        if self.has_channel("vehicle"):
            i, j, f = _segment(self._times["vehicle"], local)
            a, b = self._values["vehicle"][i], self._values["vehicle"][j]
            update.vehicle.position_m.CopyFrom(vec3(_lerp3(a["position_m"], b["position_m"], f)))
            update.vehicle.rotation.CopyFrom(rotation(
                [_lerp_angle(x, y, f) for x, y in zip(a["rotation_deg"], b["rotation_deg"])]))
            update.vehicle.velocity_mps.CopyFrom(
                vec3(_lerp3(a["velocity_mps"], b["velocity_mps"], f)))
        if self.has_channel("wipers"):
            index = max(0, bisect.bisect_right(self._times["wipers"], local) - 1)
            wipers = self._values["wipers"][index]
            update.wipers.mode = wipers["mode"]
            update.wipers.interval_s = wipers["interval_s"]
            update.wipers.blade_angle_deg.extend(wipers["blade_angle_deg"])
        if self.has_channel("weather"):
            i, j, f = _segment(self._times["weather"], local)
            a, b = self._values["weather"][i], self._values["weather"][j]
            for field in WEATHER:
                name = field["name"]
                setattr(update.weather, name,
                        interpolate(field["interpolation"], a[name], b[name], f))
        return update

    def create_request(self, mode="LOCKSTEP"):
        """The CreateSessionRequest of this scenario: its views, fps, seed and state at t = 0."""
        return pb.CreateSessionRequest(
            views=[to_view_spec(v) for v in self.views], mode=mode_value(mode), fps=self.fps,
            seed=self.seed, initial=self.at(0.0))


def _segment(times, t):
    """(i, j, f): t lies between times[i] and times[j] at fraction f; held outside the range."""
    if t <= times[0]:
        return 0, 0, 0.0
    if t >= times[-1]:
        last = len(times) - 1
        return last, last, 0.0
    j = bisect.bisect_right(times, t)
    i = j - 1
    return i, j, (t - times[i]) / (times[j] - times[i])


def _lerp3(a, b, f):
    return [x + (y - x) * f for x, y in zip(a, b)]


def _lerp_angle(a, b, f):
    """The shorter way round from a towards b (the result is not wrapped)."""
    return a + math.remainder(b - a, 360.0) * f


def interpolate(kind, a, b, f):
    """A weather field between keyframes, as weather_fields.py names its interpolation."""
    if kind == "angle":
        return _lerp_angle(a, b, f)
    value = a + (b - a) * f
    if kind == "round":
        return int(math.floor(value + 0.5))  # halves up, as C++'s round for these non-negatives
    return value


def _views(data):
    views = _require(data, "views", "views")
    if not isinstance(views, list) or not 1 <= len(views) <= MAX_VIEWS:
        raise ValueError(f"views: must be a list of 1 to {MAX_VIEWS} views")
    result, seen = [], set()
    for index, view in enumerate(views):
        path = f"views[{index}]"
        _object(view, path, VIEW_FIELDS)
        name = _require(view, "view", f"{path}.view")
        if not isinstance(name, str):
            raise ValueError(f"{path}.view: must be a view name such as \"COCKPIT\"")
        number = view_value(name, f"{path}.view")
        if number in seen:
            raise ValueError(f"{path}.view: {name} appears more than once")
        seen.add(number)
        spec = {
            "view": number,
            "width": _integer(view, "width", f"{path}.width", minimum=1, maximum=2**32 - 1),
            "height": _integer(view, "height", f"{path}.height", minimum=1, maximum=2**32 - 1),
            "jpeg_quality": _integer(view, "jpeg_quality", f"{path}.jpeg_quality", default=0,
                                     maximum=100),
            "fov_deg": _number(view, "fov_deg", f"{path}.fov_deg", default=0.0),
        }
        for field, (low, high) in LENS_RANGES.items():
            if field in view:
                spec[field] = _in_range(view[field], low, high, f"{path}.{field}")
        result.append(spec)
    return result


def _vehicle(value, path):
    _object(value, path, VEHICLE_FIELDS)
    return {field: _triple(value, field, f"{path}.{field}") for field in VEHICLE_FIELDS}


def _wipers(value, path):
    _object(value, path, WIPER_FIELDS)
    mode = _require(value, "mode", f"{path}.mode")
    if not isinstance(mode, str):
        raise ValueError(f"{path}.mode: must be a wiper mode name such as \"HIGH\"")
    angles = value.get("blade_angle_deg", [])
    if not isinstance(angles, list):
        raise ValueError(f"{path}.blade_angle_deg: must be a list of numbers")
    return {
        "mode": wiper_mode_value(mode, f"{path}.mode"),
        "interval_s": _number(value, "interval_s", f"{path}.interval_s",
                              default=DEFAULT_INTERVAL_S),
        "blade_angle_deg": [_finite(a, f"{path}.blade_angle_deg[{i}]")
                            for i, a in enumerate(angles)],
    }


def _weather(value, path):
    _object(value, path, WEATHER_FIELDS)
    result = {}
    for field in WEATHER:
        name = field["name"]
        if field["integer"]:
            result[name] = _integer(value, name, f"{path}.{name}", default=int(field["default"]),
                                    minimum=int(field["min"]), maximum=int(field["max"]))
        else:
            result[name] = _number(value, name, f"{path}.{name}", default=field["default"])
    return result


def _object(value, path, allowed):
    if not isinstance(value, dict):
        raise ValueError(f"{path}: must be an object")
    unknown = sorted(set(value) - set(allowed))
    if unknown:
        raise ValueError(f"{path}.{unknown[0]}: unknown field (allowed: {', '.join(allowed)})")


def _require(obj, key, path):
    if key not in obj:
        raise ValueError(f"{path}: missing")
    return obj[key]


def _finite(value, path):
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ValueError(f"{path}: must be a finite number, got {value!r}")
    return float(value)


def _in_range(value, low, high, path):
    value = _finite(value, path)
    if not low <= value <= high:
        raise ValueError(f"{path}: must be in [{low:g}, {high:g}], got {value:g}")
    return value


def _number(obj, key, path, default=None, positive=False):
    if key not in obj and default is not None:
        return default
    value = _finite(_require(obj, key, path), path)
    if positive and value <= 0:
        raise ValueError(f"{path}: must be > 0, got {value:g}")
    return value


def _integer(obj, key, path, default=None, minimum=0, maximum=None):
    if key not in obj and default is not None:
        return default
    value = _require(obj, key, path)
    if isinstance(value, float) and value.is_integer():
        value = int(value)
    if isinstance(value, bool) or not isinstance(value, int):
        raise ValueError(f"{path}: must be an integer, got {value!r}")
    if value < minimum:
        raise ValueError(f"{path}: must be >= {minimum}, got {value}")
    if maximum is not None and value > maximum:
        raise ValueError(f"{path}: must be <= {maximum}, got {value}")
    return value


def _boolean(obj, key, path, default):
    value = obj.get(key, default)
    if not isinstance(value, bool):
        raise ValueError(f"{path}: must be true or false, got {value!r}")
    return value


def _string(obj, key, path, default=None):
    value = obj.get(key, default) if default is not None else _require(obj, key, path)
    if not isinstance(value, str):
        raise ValueError(f"{path}: must be a string, got {value!r}")
    return value


def _triple(obj, key, path):
    value = obj.get(key, [0.0, 0.0, 0.0])
    if not isinstance(value, list) or len(value) != 3:
        raise ValueError(f"{path}: must be a list of 3 numbers, got {value!r}")
    return [_finite(v, f"{path}[{i}]") for i, v in enumerate(value)]
