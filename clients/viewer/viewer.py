"""Downpour control room: follows the server's sessions and serves them to a browser.

  python3 clients/viewer/viewer.py --server 127.0.0.1:50051 [--session ID] [--host 127.0.0.1] --port 8080

The page at / lists the server's sessions (refreshed every second) and shows the followed one:
each view's image with a HUD of its frame's stats, and plots of the last minute. Without
--session it follows the first session the server lists (or the one picked on the page) and
waits for the next one when that closes. /drive creates a realtime session owned by the viewer
and drives it along the built-in track from the keyboard (the viewer sends the Updates); the
viewer closes that session when the page is closed, stopped, or the viewer exits.

HTTP endpoints:
  /, /drive                      the pages (static/ next to this file)
  /status.json                   the followed session, its views' latest stats, the session list,
                                 the server's state and the drive's
  /api/frame/<view>.json         the latest frame's stats of one view
  /api/history.json              per view, samples of the last minute (for the plots)
  /frame/<view>.jpg[?after=N]    the latest JPEG (with ?after=N: waits up to 2 s for a newer one)
  /stream/<view>[,<view>...]     each new frame of these views as it comes, over one held
                                 connection: MJPEG (multipart/x-mixed-replace), each part with its
                                 X-View and X-Frame-Number; the pages' frames, all of a page's views
                                 on one connection (a browser holds six to a host). Before a first
                                 frame it waits up to 2 s, then answers 204 (at once when no
                                 session is followed)
  POST /api/follow               {"session_id": "..."} ("" = the first listed)
  POST /api/drive/start          {"width", "height", "fps"} all optional
  POST /api/drive/controls       {"throttle", "brake", "left", "right": bool,
                                  "wipers": "off|intermittent|low|high|single" (optional),
                                  "weather": {Weather's fields} (optional)}
  POST /api/drive/stop
"""

import argparse
import collections
import json
import math
import os
import select
import signal
import socket
import sys
import threading
import time
from http import HTTPStatus
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "python"))

import grpc  # noqa: E402
from downpour_client import (  # noqa: E402
    DownpourClient, add_security_arguments, enum_name, security_options, view_spec)
from downpour.v1 import downpour_pb2 as pb  # noqa: E402
from downpour_client.weather_fields import FIELDS as WEATHER_DEFINITION  # noqa: E402

MIN_RATE_SPAN_S = 0.5
MAX_BODY_BYTES = 64 * 1024  # a POST's JSON body
FPS_WINDOW_S = 2.0
RETRY_S = 0.5
SLOW_REQUEST_S = 2.0
MAX_STREAM_VIEWS = 8   # views on one /stream connection
STREAM_IDLE_S = 5.0    # a stream without frames this long checks that its page is still there
LIST_PERIOD_S = 1.0
HISTORY_S = 60.0
HISTORY_STEP_S = 0.25
LATE_RATIO = 0.9
BOUNDARY = "downpour-frame"
STATIC_DIR = os.path.join(HERE, "static")
UPLOT_DIR = os.path.join(HERE, "node_modules", "uplot", "dist")
VENDOR_FILES = {"uPlot.iife.min.js": "application/javascript; charset=utf-8",
                "uPlot.min.css": "text/css; charset=utf-8"}
STATIC_TYPES = {".html": "text/html; charset=utf-8", ".js": "application/javascript; charset=utf-8",
                ".css": "text/css; charset=utf-8", ".svg": "image/svg+xml"}


def _finite(value, name):
    """A JSON number from a page, as a float; ValueError (a 400) for anything else."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ValueError(f"{name}: a number is needed")
    return float(value)


def log(message):
    print(f"viewer: {message}", file=sys.stderr, flush=True)


class OnceLog:
    """Logs a message once per state: the same message again is not repeated."""

    def __init__(self):
        self._lock = threading.Lock()
        self._last = {}

    def __call__(self, key, message):
        with self._lock:
            if self._last.get(key) == message:
                return
            self._last[key] = message
        if message:
            log(message)


def describe_error(error, session_id=""):
    """A short sentence for an RpcError, for the page's banner and the log."""
    code = error.code() if hasattr(error, "code") else None
    details = error.details() if hasattr(error, "details") else str(error)
    if code == grpc.StatusCode.UNAVAILABLE:
        return "server unreachable"
    if code == grpc.StatusCode.NOT_FOUND:
        return f"session {session_id} ended" if session_id else f"not found: {details}"
    if code == grpc.StatusCode.DEADLINE_EXCEEDED:
        return "server not answering"
    name = code.name if code is not None else "error"
    return f"{name}: {details}"


def _round(value, digits=3):
    return round(float(value), digits)


def _road_state(value):
    try:
        return pb.RoadState.Name(value).removeprefix("ROAD_").lower()
    except ValueError:
        return str(value)


def frame_info(frame):
    """The JSON of a Frame without its JPEG."""
    stats = frame.stats
    roads = stats.road_states
    place = frame.ego_place
    return {
        "view": enum_name(pb.View, frame.view).lower(),
        "session_id": frame.session_id,
        "frame_number": frame.frame_number,
        "sim_time_s": _round(frame.sim_time_s),
        "client_time_s": _round(frame.client_time_s),
        "width": frame.width, "height": frame.height, "jpeg_bytes": len(frame.jpeg),
        "render_ms": _round(stats.render_ms), "readback_ms": _round(stats.readback_ms),
        "encode_ms": _round(stats.encode_ms), "latency_ms": _round(stats.latency_ms),
        "drops_on_glass": stats.drops_on_glass,
        "glass_wet_fraction": _round(stats.glass_wet_fraction, 4),
        "view_wet_fraction": _round(stats.view_wet_fraction, 4),
        "frames_dropped": stats.frames_dropped, "rain_streaks": stats.rain_streaks,
        "visibility_m": _round(stats.visibility_m, 1),
        "road_states": {"dry": _round(roads.dry, 4), "wet": _round(roads.wet, 4),
                        "drench": _round(roads.drench, 4), "puddle": _round(roads.puddle, 4)},
        "tires": [{"water_mm": _round(t.water_mm), "standing_mm": _round(t.standing_mm),
                   "state": _road_state(t.state)} for t in frame.tires],
        "ego_place": {"road_id": place.road_id, "s_m": _round(place.s_m, 2),
                      "t_m": _round(place.t_m, 2), "lane_id": place.lane_id,
                      "lane_offset_m": _round(place.lane_offset_m, 2),
                      "on_road": place.on_road} if frame.HasField("ego_place") else None,
    }


def session_info(info):
    """The JSON of a SessionInfo, with whether a realtime session is late."""
    mode = enum_name(pb.Mode, info.mode).lower()
    started = info.frames_rendered >= max(4, info.fps * 2)
    late = (mode == "realtime" and started and info.fps > 0 and
            info.achieved_fps < LATE_RATIO * info.fps)
    return {
        "session_id": info.session_id, "mode": mode, "fps": _round(info.fps, 2),
        "achieved_fps": _round(info.achieved_fps, 2), "frames_late": info.frames_late,
        "frames_rendered": info.frames_rendered, "sim_time_s": _round(info.sim_time_s, 2),
        "idle_s": _round(info.idle_s, 1), "owner": info.owner,
        "road_network": info.road_network, "roads": info.roads,
        "endpoint": getattr(info, "endpoint", ""),
        "views": [{"view": enum_name(pb.View, v.view).lower(), "width": v.width,
                   "height": v.height} for v in info.views],
        "late": late,
    }


class LatestFrames:
    """The latest frame of each view of the followed session; readers wait on a Condition."""

    def __init__(self):
        self.condition = threading.Condition()
        self.session_id = ""
        self.generation = 0  # counts follow() calls, so that readers notice a new stream
        self.state = "waiting"
        self.error = ""
        self.closed = False
        self.session_fps = 0.0  # the followed session's achieved fps, from the session list
        self._frames = {}    # view name -> Frame; guarded by condition
        self._arrivals = {}  # view name -> deque of arrival times; guarded by condition
        self._history = {}   # view name -> deque of samples; guarded by condition
        self._last_sample = {}

    def follow(self, session_id):
        with self.condition:
            self.session_id, self.state, self.error = session_id, "watching", ""
            self.generation += 1
            self._clear()
            self.condition.notify_all()

    def unfollow(self, error=""):
        with self.condition:
            self.session_id, self.state, self.error = "", "waiting", error
            self._clear()
            self.condition.notify_all()

    def _clear(self):
        self._frames.clear()
        self._arrivals.clear()
        self._history.clear()
        self._last_sample.clear()
        self.session_fps = 0.0

    def put(self, frame):
        view = enum_name(pb.View, frame.view).lower()
        now = time.monotonic()
        with self.condition:
            self._frames[view] = frame
            arrivals = self._arrivals.setdefault(view, collections.deque())
            arrivals.append(now)
            self._trim(arrivals)
            if now - self._last_sample.get(view, -1e9) >= HISTORY_STEP_S:
                self._last_sample[view] = now
                self._sample(view, frame, arrivals)
            self.condition.notify_all()

    def _sample(self, view, frame, arrivals):
        stats, roads = frame.stats, frame.stats.road_states
        history = self._history.setdefault(view, collections.deque())
        history.append((round(time.time(), 3), round(_rate(arrivals), 2),
                        round(self.session_fps, 2), round(stats.latency_ms, 2),
                        round(stats.render_ms, 2), round(stats.encode_ms, 2),
                        round(stats.glass_wet_fraction, 4), round(stats.view_wet_fraction, 4),
                        round(roads.wet + roads.drench + roads.puddle, 4)))
        horizon = time.time() - HISTORY_S
        while history and history[0][0] < horizon:
            history.popleft()

    def close(self):
        with self.condition:
            self.closed = True
            self.condition.notify_all()

    def latest(self, view):
        """(generation, the view's latest frame or None)."""
        with self.condition:
            return self.generation, self._frames.get(view)

    def wait_any_newer(self, views, generation, seen, timeout_s):
        """[(view, frame)] of those views whose latest frame is not the one `seen` names (view ->
        frame number); None once that stream is gone or no session is followed; [] after
        timeout_s."""
        deadline = time.monotonic() + timeout_s
        with self.condition:
            while True:
                if self.closed or self.generation != generation or self.state != "watching":
                    return None
                newer = [(v, f) for v in views for f in [self._frames.get(v)]
                         if f is not None and f.frame_number != seen.get(v)]
                remaining = deadline - time.monotonic()
                if newer or remaining <= 0:
                    return newer
                self.condition.wait(remaining)

    def status(self):
        with self.condition:
            views = []
            for view in sorted(self._frames, key=lambda v: self._frames[v].view):
                frame, arrivals = self._frames[view], self._arrivals[view]
                self._trim(arrivals)
                views.append({
                    "view": view, "frame_number": frame.frame_number,
                    "sim_time_s": round(frame.sim_time_s, 3), "width": frame.width,
                    "height": frame.height, "fps": round(_rate(arrivals), 1),
                    "frames_dropped": frame.stats.frames_dropped,
                    "stats": frame_info(frame),
                })
            return {"state": self.state, "session_id": self.session_id,
                    "generation": self.generation, "error": self.error, "views": views}

    def frame_json(self, view):
        with self.condition:
            frame = self._frames.get(view)
            if frame is None:
                return None
            info = frame_info(frame)
            arrivals = self._arrivals[view]
            self._trim(arrivals)
            info["fps"] = round(_rate(arrivals), 1)
            info["generation"] = self.generation
            return info

    def history(self):
        with self.condition:
            columns = ("t", "fps", "session_fps", "latency_ms", "render_ms", "encode_ms",
                       "glass_wet", "view_wet", "road_wet")
            views = {}
            for view, samples in self._history.items():
                views[view] = {name: [s[i] for s in samples] for i, name in enumerate(columns)}
            return {"session_id": self.session_id, "generation": self.generation,
                    "window_s": HISTORY_S, "views": views}

    @staticmethod
    def _trim(arrivals):
        horizon = time.monotonic() - FPS_WINDOW_S
        while arrivals and arrivals[0] < horizon:
            arrivals.popleft()


def _rate(arrivals):
    """Frames per second over the arrival times kept; 0 until they span half a second, so a
    burst of a few frames after a stall does not read as a huge rate."""
    if len(arrivals) < 2 or arrivals[-1] - arrivals[0] < MIN_RATE_SPAN_S:
        return 0.0
    return (len(arrivals) - 1) / (arrivals[-1] - arrivals[0])


class SessionDirectory(threading.Thread):
    """Lists the server's sessions every second; knows whether the server answers."""

    def __init__(self, client, frames, once_log, target):
        super().__init__(name="sessions", daemon=True)
        self.client = client
        self.frames = frames
        self.once_log = once_log
        self.target = target
        self._lock = threading.Lock()
        self._sessions = []  # guarded by _lock
        self._server = {"state": "connecting", "error": "", "renderer": "", "version": ""}
        self._stopping = threading.Event()
        self._stats_due = 0.0

    def stop(self):
        self._stopping.set()

    def run(self):
        while not self._stopping.is_set():
            self.refresh()
            self._stopping.wait(LIST_PERIOD_S)

    def refresh(self):
        try:
            sessions = [session_info(s) for s in self.client.list_sessions()]
            if time.monotonic() >= self._stats_due:
                stats = self.client.get_stats()
                with self._lock:
                    self._server.update(renderer=stats.renderer,
                                        version=getattr(stats, "version", ""))
                self._stats_due = time.monotonic() + 30.0
        except grpc.RpcError as error:
            message = describe_error(error)
            with self._lock:
                self._server.update(state="down", error=message)
                self._sessions = []
            self._stats_due = 0.0
            self.once_log("server", f"server {self.target}: {message}; retrying every second")
            return
        with self._lock:
            was_down = self._server["state"] == "down"
            self._server.update(state="up", error="")
            self._sessions = sessions
        self.once_log("server", f"server {self.target} is back" if was_down else "")
        followed = self.frames.session_id
        for s in sessions:
            if s["session_id"] == followed:
                self.frames.session_fps = s["achieved_fps"]

    def sessions(self):
        with self._lock:
            return list(self._sessions)

    def server(self):
        with self._lock:
            return dict(self._server)


class Follower(threading.Thread):
    """Finds the session to follow and copies its frames into a LatestFrames."""

    def __init__(self, client, frames, session_id=None, max_fps=0.0, once_log=None):
        super().__init__(name="follower", daemon=True)
        self.client = client
        self.frames = frames
        self.session_id = session_id  # --session: pinned
        self.max_fps = max_fps
        self.once_log = once_log or OnceLog()
        self._stopping = threading.Event()
        self._wake = threading.Event()
        self._lock = threading.Lock()
        self._call = None      # guarded by _lock
        self._selected = None  # picked on the page; guarded by _lock

    def stop(self):
        self._stopping.set()
        self._wake.set()
        self._cancel()

    def select(self, session_id):
        """Follow this session now ("" or None: back to --session or the first listed)."""
        with self._lock:
            self._selected = session_id or None
        self._wake.set()
        self._cancel()

    def selected(self):
        with self._lock:
            return self._selected

    def _cancel(self):
        with self._lock:
            if self._call is not None:
                self._call.cancel()

    def run(self):
        while not self._stopping.is_set():
            self._wake.clear()
            try:
                session_id = self.selected() or self.session_id or self._first_session()
                if session_id:
                    self._watch(session_id)
                    continue
                if self.frames.state != "waiting" or self.frames.error:
                    self.frames.unfollow()
            except grpc.RpcError as error:
                self.frames.unfollow(describe_error(error))
            self._wake.wait(RETRY_S)

    def _first_session(self):
        sessions = self.client.list_sessions()
        return sessions[0].session_id if sessions else None

    def _watch(self, session_id):
        with self._lock:
            if self._stopping.is_set():
                return
            self._call = self.client.watch_frames(session_id, max_fps=self.max_fps)
            if self._wake.is_set():  # picked another while this one was being chosen
                self._call.cancel()
        self.frames.follow(session_id)
        self.once_log("follow", f"following session {session_id}")
        try:
            for frame in self._call:
                self.frames.put(frame)
            self._ended(session_id, "")
        except grpc.RpcError as error:
            if self._stopping.is_set():
                return
            if error.code() == grpc.StatusCode.CANCELLED and self._wake.is_set():
                return  # another session was picked
            message = describe_error(error, session_id)
            self._ended(session_id, message)
            self._wake.wait(RETRY_S)
        finally:
            with self._lock:
                self._call = None

    def _ended(self, session_id, message):
        with self._lock:
            if self._selected == session_id:
                self._selected = None  # a picked session that ended: back to the default
        self.frames.unfollow(message)
        if message.startswith("server"):
            return  # the session directory logs the server's state
        self.once_log("follow", f"session {session_id} ended")


class Track:
    """The server's built-in test track (server/sim/track.cpp): a 900 m straight along +x from
    the origin, a 250 m radius left half circle, the straight back and another half circle; a
    10 m crest on the back straight; two 3.5 m lanes each way and 1.5 m shoulders, crowned 2%."""

    STRAIGHT = 900.0
    RADIUS = 250.0
    LANE_WIDTH = 3.5
    PAVED_HALF_WIDTH = 2 * 3.5 + 1.5
    CROWN = 0.02

    def __init__(self):
        arc = math.pi * self.RADIUS
        self.segments = []  # (s0, length, curvature, x0, y0, heading0)
        x = y = heading = s = 0.0
        for length, curvature in ((self.STRAIGHT, 0.0), (arc, 1.0 / self.RADIUS),
                                  (self.STRAIGHT, 0.0), (arc, 1.0 / self.RADIUS)):
            self.segments.append((s, length, curvature, x, y, heading))
            x, y, _ = self._point(self.segments[-1], length)
            s += length
            heading += curvature * length
        self.length = s
        self.crest = (self.STRAIGHT + arc + self.STRAIGHT * 0.5, 350.0, 10.0)

    @staticmethod
    def _point(segment, d):
        _, _, curvature, x0, y0, heading0 = segment
        if curvature == 0.0:
            return x0 + d * math.cos(heading0), y0 + d * math.sin(heading0), heading0
        r = 1.0 / curvature
        heading = heading0 + d * curvature
        cx, cy = x0 - r * math.sin(heading0), y0 + r * math.cos(heading0)
        return cx + r * math.sin(heading), cy - r * math.cos(heading), heading

    def wrap(self, s):
        return s % self.length

    def at(self, s):
        """(x, y, z, heading_rad, curvature, grade) of the centreline at s."""
        s = self.wrap(s)
        segment = self.segments[-1]
        for candidate in self.segments:
            if s < candidate[0] + candidate[1]:
                segment = candidate
                break
        x, y, heading = self._point(segment, s - segment[0])
        centre, half, height = self.crest
        u = (s - centre) / half
        z = grade = 0.0
        if abs(u) < 1.0:
            z = height * 0.5 * (1.0 + math.cos(math.pi * u))
            grade = -height * 0.5 * math.pi / half * math.sin(math.pi * u)
        return x, y, z, heading, segment[2], grade

    def section_height(self, lateral):
        return -self.CROWN * min(abs(lateral), self.PAVED_HALF_WIDTH)


class Car:
    """A kinematic car in the track's frame: s along the centreline, lateral offset (left
    positive), heading relative to the road, speed. Without steering input it keeps its heading
    along the road (a lane-keeping assist); A/D turn it."""

    ACCEL = 3.5        # m/s^2 at full throttle from rest
    BRAKE = 8.0        # m/s^2
    MAX_SPEED = 45.0   # m/s
    ROLLING = 0.15     # m/s^2
    DRAG = 0.0005      # 1/m (a = DRAG v^2)
    LATERAL_ACCEL = 3.0
    STEER_RATE = 3.0   # steering input per second, [-1, 1]
    ASSIST_GAIN = 1.5  # 1/s: how fast the heading error relative to the road decays

    def __init__(self, track, s=20.0, lateral=-5.25):
        self.track = track
        self.s, self.lateral, self.heading_error, self.speed = s, lateral, 0.0, 0.0
        self.steer = 0.0
        self.odometer = 0.0

    def step(self, dt, throttle, brake, steer_input):
        accel = (self.ACCEL * (1.0 - self.speed / self.MAX_SPEED) if throttle else 0.0)
        accel -= self.BRAKE if brake else 0.0
        if self.speed > 0:
            accel -= self.ROLLING + self.DRAG * self.speed * self.speed
        self.speed = min(self.MAX_SPEED, max(0.0, self.speed + accel * dt))
        target = max(-1.0, min(1.0, float(steer_input)))
        step = self.STEER_RATE * dt
        self.steer += max(-step, min(step, target - self.steer))
        if target == 0.0 and abs(self.steer) < step:
            self.steer = 0.0
        _, _, _, _, road_curvature, _ = self.track.at(self.s)
        v = self.speed
        # The car's path curvature: the road's, a correction of the heading error, the driver's.
        user = min(1.0 / 8.0, self.LATERAL_ACCEL / max(v, 4.0) ** 2) * self.steer
        correction = 0.0
        if self.steer == 0.0 and v > 0.1:
            correction = -self.ASSIST_GAIN * self.heading_error / v
        feedforward = road_curvature / max(0.2, 1.0 - road_curvature * self.lateral)
        curvature = feedforward + correction + user
        along = v * math.cos(self.heading_error) / max(0.2, 1.0 - road_curvature * self.lateral)
        self.heading_error += (v * curvature - road_curvature * along) * dt
        self.heading_error = max(-1.0, min(1.0, self.heading_error))
        self.lateral += v * math.sin(self.heading_error) * dt
        limit = self.track.PAVED_HALF_WIDTH - 1.0
        if abs(self.lateral) > limit:
            self.lateral = math.copysign(limit, self.lateral)
            if self.heading_error * self.lateral > 0:
                self.heading_error = 0.0
        self.s = self.track.wrap(self.s + along * dt)
        self.odometer += v * dt

    def vehicle_state(self):
        x, y, z, heading, _, grade = self.track.at(self.s)
        left = (-math.sin(heading), math.cos(heading))
        yaw = heading + self.heading_error
        z += self.track.section_height(self.lateral)
        state = pb.VehicleState()
        state.position_m.x = x + self.lateral * left[0]
        state.position_m.y = y + self.lateral * left[1]
        state.position_m.z = z
        state.rotation.yaw_deg = math.degrees(yaw)
        state.rotation.pitch_deg = -math.degrees(math.atan(grade))
        state.velocity_mps.x = self.speed * math.cos(yaw)
        state.velocity_mps.y = self.speed * math.sin(yaw)
        state.velocity_mps.z = self.speed * grade
        return state


# The page may set every weather field but the streak count, within the contract's ranges.
WEATHER_RANGES = {field["name"]: (field["min"], field["max"])
                  for field in WEATHER_DEFINITION if not field["integer"]}
DEFAULT_WEATHER = {"rain_rate_mm_h": 20.0, "wind_speed_mps": 3.0, "wind_direction_deg": 60.0,
                   "fog_density": 0.05, "cloudiness": 0.8, "sun_altitude_deg": 30.0,
                   "sun_azimuth_deg": 200.0, "rain_angle_deg": 0.0}
WIPER_MODES = {"off": pb.WIPER_OFF, "intermittent": pb.WIPER_INTERMITTENT, "low": pb.WIPER_LOW,
               "high": pb.WIPER_HIGH, "single": pb.WIPER_SINGLE}
INTERMITTENT_S = 4.0
CONTROLS_STALE_S = 1.0   # keys are released when the page has not been heard for this long
PAGE_GONE_S = 15.0       # the drive session is closed when the page has not been heard this long


class DriveController:
    """The viewer's own realtime session, driven from the page's keys at UPDATE_HZ."""

    UPDATE_HZ = 20.0

    def __init__(self, client, follower, once_log):
        self.client = client
        self.follower = follower
        self.once_log = once_log
        self.track = Track()
        self._lock = threading.Lock()
        self._thread = None
        self._stop = threading.Event()
        self._reset()

    def _reset(self):
        self.session_id = ""
        self.state = "idle"  # idle, starting, driving, ended
        self.error = ""
        self.car = Car(self.track)
        self.keys = {"throttle": False, "brake": False, "left": False, "right": False}
        self.heard = time.monotonic()
        self.weather = dict(DEFAULT_WEATHER)  # as asked on the page
        self.weather_in_effect = {}           # as last accepted by the server
        self.pending_weather = False
        self.wipers = "off"
        self.wipers_in_effect = ""
        self.pending_wipers = False
        self.sim_time_s = 0.0
        self.updates_sent = 0
        self.server_sim_time_s = 0.0

    def start(self, width=480, height=270, fps=20.0):
        # Checked before anything changes: a bad request leaves the drive as it was.
        width = int(max(64, min(1920, _finite(width, "width"))))
        height = int(max(64, min(1080, _finite(height, "height"))))
        fps = float(max(1.0, min(60.0, _finite(fps, "fps"))))
        with self._lock:
            if self.state in ("starting", "driving"):
                self.heard = time.monotonic()
                return self._state_locked()
            self._reset()
            self.state = "starting"
        initial = pb.Update(sim_time_s=0.0)
        initial.vehicle.CopyFrom(self.car.vehicle_state())
        initial.weather.CopyFrom(pb.Weather(**self.weather))
        initial.wipers.CopyFrom(pb.WiperState(mode=pb.WIPER_OFF))
        try:
            info = self.client.create_session(
                [view_spec("COCKPIT", width, height), view_spec("ROAD", width, height)],
                mode="REALTIME", fps=fps, initial=initial)
        except grpc.RpcError as error:
            with self._lock:
                self.state, self.error = "idle", describe_error(error)
            log(f"drive: could not create a session: {self.error}")
            return self.state_json()
        with self._lock:
            self.session_id = info.session_id
            self.state = "driving"
            self.weather_in_effect = dict(self.weather)
            self.wipers_in_effect = "off"
            self.heard = time.monotonic()
            self._stop = threading.Event()
            self._thread = threading.Thread(target=self._loop, name="drive",
                                            args=(info.session_id, self._stop), daemon=True)
            self._thread.start()
        log(f"drive: session {info.session_id} created ({width}x{height}, {fps:g} fps, "
            "cockpit and road)")
        self.follower.select(info.session_id)
        return self.state_json()

    def controls(self, body):
        with self._lock:
            self.heard = time.monotonic()
            for key in self.keys:
                if key in body:
                    self.keys[key] = bool(body[key])
            wipers = body.get("wipers")
            if wipers is not None:
                wipers = str(wipers).lower()
                if wipers not in WIPER_MODES:
                    raise ValueError(f"wipers: one of {', '.join(WIPER_MODES)}")
                self.wipers, self.pending_wipers = wipers, True
            weather = body.get("weather")
            if weather is not None:
                if not isinstance(weather, dict):
                    raise ValueError("weather: an object")
                for name, value in weather.items():
                    if name not in WEATHER_RANGES:
                        raise ValueError(f"weather: unknown field {name}")
                    low, high = WEATHER_RANGES[name]
                    value = float(value)
                    if not math.isfinite(value):
                        raise ValueError(f"weather.{name}: not a number")
                    self.weather[name] = max(low, min(high, value))
                self.pending_weather = True
            return self._state_locked()

    def stop(self, reason="stopped"):
        with self._lock:
            session_id, thread = self.session_id, self._thread
            self._stop.set()
            if self.state in ("starting", "driving"):
                self.state = "ended"
                self.error = reason
            self._thread = None
        if thread is not None and thread is not threading.current_thread():
            thread.join(timeout=2)
        if session_id:
            try:
                self.client.close_session(session_id)
                log(f"drive: session {session_id} closed ({reason})")
            except grpc.RpcError as error:
                if error.code() != grpc.StatusCode.NOT_FOUND:
                    log(f"drive: could not close session {session_id}: "
                        f"{describe_error(error, session_id)}")
            with self._lock:
                if self.session_id == session_id:
                    self.session_id = ""
        return self.state_json()

    def _loop(self, session_id, stop):
        period = 1.0 / self.UPDATE_HZ
        last = time.monotonic()
        next_tick = last
        while not stop.is_set():
            next_tick += period
            stop.wait(max(0.0, next_tick - time.monotonic()))
            if stop.is_set():
                return
            now = time.monotonic()
            dt, last = min(0.2, now - last), now
            if now < next_tick - 1.0 or now > next_tick + 1.0:
                next_tick = now
            with self._lock:
                quiet = now - self.heard
                if quiet > PAGE_GONE_S:
                    gone = True
                else:
                    gone = False
                    fresh = quiet <= CONTROLS_STALE_S
                    keys = {k: v and fresh for k, v in self.keys.items()}
                    self.car.step(dt, keys["throttle"], keys["brake"],
                                  (1.0 if keys["left"] else 0.0) - (1.0 if keys["right"] else 0.0))
                    self.sim_time_s += dt
                    update = pb.Update(sim_time_s=self.sim_time_s)
                    update.vehicle.CopyFrom(self.car.vehicle_state())
                    weather = wipers = None
                    if self.pending_weather:
                        weather = dict(self.weather)
                        update.weather.CopyFrom(pb.Weather(**weather))
                        self.pending_weather = False
                    if self.pending_wipers:
                        wipers = self.wipers
                        update.wipers.CopyFrom(pb.WiperState(
                            mode=WIPER_MODES[wipers],
                            interval_s=INTERMITTENT_S if wipers == "intermittent" else 0.0))
                        self.pending_wipers = False
            if gone:
                threading.Thread(target=self.stop, args=("the page went away",),
                                 daemon=True).start()
                return
            try:
                server_time = self.client.update(session_id, update)
            except grpc.RpcError as error:
                message = describe_error(error, session_id)
                with self._lock:
                    if stop.is_set() or self.session_id != session_id:
                        return  # a late answer for a drive already stopped: not the new one's
                    if weather is not None:
                        self.pending_weather = True
                    if wipers is not None:
                        self.pending_wipers = True
                    self.error = message
                    if error.code() == grpc.StatusCode.NOT_FOUND:
                        self.state, self.session_id = "ended", ""
                self.once_log("drive", f"drive: {message}")
                if error.code() == grpc.StatusCode.NOT_FOUND:
                    return
                stop.wait(RETRY_S)
                continue
            with self._lock:
                if stop.is_set() or self.session_id != session_id:
                    return
                self.updates_sent += 1
                self.server_sim_time_s = server_time
                self.error = ""
                if weather is not None:
                    self.weather_in_effect = weather
                if wipers is not None:
                    self.wipers_in_effect = wipers
            self.once_log("drive", "")

    def _state_locked(self):
        car = self.car
        return {
            "state": self.state, "session_id": self.session_id, "error": self.error,
            "speed_mps": round(car.speed, 2), "speed_kmh": round(car.speed * 3.6, 1),
            "s_m": round(car.s, 1), "lateral_m": round(car.lateral, 2),
            "heading_error_deg": round(math.degrees(car.heading_error), 1),
            "steer": round(car.steer, 2), "odometer_m": round(car.odometer, 1),
            "keys": dict(self.keys), "wipers": self.wipers,
            "wipers_in_effect": self.wipers_in_effect,
            "weather": dict(self.weather), "weather_in_effect": dict(self.weather_in_effect),
            "sim_time_s": round(self.sim_time_s, 2), "updates_sent": self.updates_sent,
        }

    def state_json(self):
        with self._lock:
            return self._state_locked()


class ViewerHandler(BaseHTTPRequestHandler):
    frames = None     # LatestFrames, set by make_server
    directory = None  # SessionDirectory or None
    follower = None   # Follower or None
    drive = None      # DriveController or None

    def _host_allowed(self):
        """Bound to loopback, the page answers only to loopback names, so that a web page whose
        name was made to resolve to 127.0.0.1 (DNS rebinding) cannot read or drive it."""
        if not self.loopback_only:
            return True
        host = (self.headers.get("Host") or "").rsplit(":", 1)[0].strip("[]").lower()
        return host in ("localhost", "127.0.0.1", "::1", "")

    def _same_origin(self):
        """A POST changes what the viewer does with its token: only the viewer's own pages may
        send one (a browser names the page's origin; other clients, such as tests, send none)."""
        site = self.headers.get("Sec-Fetch-Site")
        if site is not None:
            return site == "same-origin"
        origin = self.headers.get("Origin")
        return origin is None or origin == f"http://{self.headers.get('Host', '')}"

    def do_GET(self):
        if not self._host_allowed():
            self._send(HTTPStatus.FORBIDDEN, "text/plain", b"unknown host name\n")
            return
        path, _, query = self.path.partition("?")
        params = dict(p.partition("=")[::2] for p in query.split("&") if p)
        if path in ("/", "/index.html"):
            self._static("index.html")
        elif path in ("/drive", "/drive.html"):
            self._static("drive.html")
        elif path.startswith("/static/"):
            self._static(path[len("/static/"):])
        elif path.startswith("/vendor/"):
            self._vendor(path[len("/vendor/"):])
        elif path == "/status.json":
            self._json(self._status())
        elif path == "/api/sessions.json":
            self._json({"server": self._server(), "sessions": self._sessions()})
        elif path == "/api/history.json":
            self._json(self.frames.history())
        elif path == "/api/drive/state.json":
            self._json(self.drive.state_json() if self.drive else {"state": "unavailable"})
        elif path.startswith("/api/frame/") and path.endswith(".json"):
            info = self.frames.frame_json(path[len("/api/frame/"):-len(".json")].lower())
            if info is None:
                self._json({"error": "no frame for this view"}, HTTPStatus.NOT_FOUND)
            else:
                if self.drive and info["session_id"] == self.drive.session_id:
                    info["weather"] = self.drive.state_json()["weather_in_effect"]
                self._json(info)
        elif path.startswith("/frame/") and path.endswith(".jpg"):
            self._frame(path[len("/frame/"):-len(".jpg")].lower(), params.get("after"))
        elif path.startswith("/stream/"):
            self._stream(path[len("/stream/"):].lower().split(","))
        else:
            self._send(HTTPStatus.NOT_FOUND, "text/plain", b"not found\n")

    def do_POST(self):
        path = self.path.split("?", 1)[0]
        if not self._host_allowed() or not self._same_origin():
            self._send(HTTPStatus.FORBIDDEN, "text/plain", b"not from this viewer's pages\n")
            return
        try:
            length = int(self.headers.get("Content-Length") or 0)
            if not 0 <= length <= MAX_BODY_BYTES:
                self.close_connection = True
                raise ValueError(f"the body must be 0 to {MAX_BODY_BYTES} bytes")
            raw = self.rfile.read(length) if length else b""
            body = json.loads(raw) if raw.strip() else {}
            if not isinstance(body, dict):
                raise ValueError("the body must be a JSON object")
            if path == "/api/follow":
                if self.follower is None:
                    raise ValueError("no follower")
                self.follower.select(str(body.get("session_id") or ""))
                self._json({"selected": self.follower.selected() or ""})
            elif path == "/api/drive/start" and self.drive:
                self._json(self.drive.start(body.get("width", 480), body.get("height", 270),
                                            body.get("fps", 20)))
            elif path == "/api/drive/controls" and self.drive:
                self._json(self.drive.controls(body))
            elif path == "/api/drive/stop" and self.drive:
                self._json(self.drive.stop(str(body.get("reason") or "stopped on the page")))
            else:
                self._send(HTTPStatus.NOT_FOUND, "text/plain", b"not found\n")
        except (ValueError, TypeError, RecursionError) as error:
            self._json({"error": str(error)}, HTTPStatus.BAD_REQUEST)

    def _status(self):
        status = self.frames.status()
        status["server"] = self._server()
        status["sessions"] = self._sessions()
        status["selected"] = (self.follower.selected() or "") if self.follower else ""
        status["drive"] = self.drive.state_json() if self.drive else None
        status["plots"] = os.path.isfile(os.path.join(UPLOT_DIR, "uPlot.iife.min.js"))
        return status

    def _server(self):
        return self.directory.server() if self.directory else {"state": "unknown"}

    def _sessions(self):
        return self.directory.sessions() if self.directory else []

    def _static(self, name):
        if "/" in name or name.startswith(".") or os.path.splitext(name)[1] not in STATIC_TYPES:
            self._send(HTTPStatus.NOT_FOUND, "text/plain", b"not found\n")
            return
        self._file(os.path.join(STATIC_DIR, name), STATIC_TYPES[os.path.splitext(name)[1]])

    def _vendor(self, name):
        if name not in VENDOR_FILES:
            self._send(HTTPStatus.NOT_FOUND, "text/plain", b"not found\n")
            return
        path = os.path.join(UPLOT_DIR, name)
        if not os.path.isfile(path):
            # Without node_modules the page runs without plots (and says so): an empty file, not
            # a 404 in the browser's console.
            self._send(HTTPStatus.OK, VENDOR_FILES[name],
                       b"/* uPlot is not installed: npm ci --prefix clients/viewer */\n")
            return
        self._file(path, VENDOR_FILES[name])

    def _file(self, path, content_type):
        try:
            with open(path, "rb") as file:
                body = file.read()
        except (OSError, ValueError):  # ValueError: a NUL in the name
            self._send(HTTPStatus.NOT_FOUND, "text/plain", b"not found\n")
            return
        self._send(HTTPStatus.OK, content_type, body)

    def _frame(self, view, after):
        generation, frame = self.frames.latest(view)
        if after is not None and (frame is None or str(frame.frame_number) == after):
            # A client's frame loop: wait for the next frame (or the first) up to 2 s; none yet
            # is "204 No Content", not an error. (The pages read /stream.)
            newer = self.frames.wait_any_newer([view], generation,
                                               {view: frame.frame_number} if frame else {}, 2.0)
            frame = newer[0][1] if newer else None
            if frame is None:
                _, frame = self.frames.latest(view)
            if frame is None:
                self._send(HTTPStatus.NO_CONTENT, "text/plain", b"")
                return
        if frame is None:
            self._send(HTTPStatus.NOT_FOUND, "text/plain", b"no frame for this view\n")
            return
        self._send(HTTPStatus.OK, "image/jpeg", frame.jpeg,
                   {"X-Frame-Number": str(frame.frame_number), "X-Session": frame.session_id})

    def _stream(self, views):
        views = list(dict.fromkeys(v for v in views if v))[:MAX_STREAM_VIEWS]
        seen = {}
        newer = None
        if views:
            generation, _ = self.frames.latest(views[0])
            # A page asks as soon as its session exists: its first frames may be on their way.
            newer = self.frames.wait_any_newer(views, generation, seen, timeout_s=2.0)
        if not newer:
            self._send(HTTPStatus.NO_CONTENT, "text/plain", b"")
            return
        try:
            self.send_response(HTTPStatus.OK)
            self.send_header("Content-Type", f"multipart/x-mixed-replace; boundary={BOUNDARY}")
            self.send_header("Cache-Control", "no-store")
            self.end_headers()
            while newer is not None:
                for view, frame in newer:
                    self.wfile.write(f"--{BOUNDARY}\r\nContent-Type: image/jpeg\r\n"
                                     f"X-View: {view}\r\nX-Frame-Number: {frame.frame_number}\r\n"
                                     f"Content-Length: {len(frame.jpeg)}\r\n\r\n".encode())
                    self.wfile.write(frame.jpeg)
                    self.wfile.write(b"\r\n")
                    seen[view] = frame.frame_number
                self.wfile.flush()
                newer = self.frames.wait_any_newer(views, generation, seen, STREAM_IDLE_S)
                if newer == [] and self._client_gone():
                    break
        except (BrokenPipeError, ConnectionResetError):
            pass
        self.close_connection = True

    def _client_gone(self):
        """Whether the page hung up: it sends nothing after its request, so a readable socket
        means the end of the connection (a paused session's stream would wait on else)."""
        try:
            readable, _, _ = select.select([self.connection], [], [], 0)
            return bool(readable) and self.connection.recv(1, socket.MSG_PEEK) == b""
        except OSError:
            return True

    def _json(self, value, status=HTTPStatus.OK):
        self._send(status, "application/json", json.dumps(value).encode())

    def _send(self, status, content_type, body, headers=None):
        try:
            self.send_response(status)
            self.send_header("Content-Type", content_type)
            self.send_header("Content-Length", str(len(body)))
            self.send_header("Cache-Control", "no-store")
            for key, value in (headers or {}).items():
                self.send_header(key, value)
            self.end_headers()
            self.wfile.write(body)
        except (BrokenPipeError, ConnectionResetError):
            self.close_connection = True

    def log_message(self, format, *args):
        pass

    def handle_one_request(self):
        # A request (but a frame's, which waits for the next frame by design) that took longer than
        # SLOW_REQUEST_S goes to the log: the page's polls and controls should take milliseconds.
        start = time.monotonic()
        super().handle_one_request()
        took = time.monotonic() - start
        path = (getattr(self, "path", "") or "").split("?", 1)[0]
        if took > SLOW_REQUEST_S and path and not path.startswith(("/frame/", "/stream/")):
            log(f"slow request: {getattr(self, 'command', '')} {path} took {took:.1f} s")


class ViewerServer(ThreadingHTTPServer):
    # Every request is a connection of its own (HTTP/1.0): a page opens some ten a second (its
    # controls and its polls; its frames come over one held stream). socketserver's backlog of 5
    # overflows when a loaded machine is slow to accept, and a connection refused that way waits
    # for the browser's retries (1, 2, 4, 8 s: a page unheard for 15 s loses its drive).
    request_queue_size = 128
    daemon_threads = True


def make_server(frames, port, host="127.0.0.1", directory=None, follower=None, drive=None):
    handler = type("BoundViewerHandler", (ViewerHandler,), {
        "frames": frames, "directory": directory, "follower": follower, "drive": drive,
        "loopback_only": host in ("127.0.0.1", "localhost", "::1")})
    return ViewerServer((host, port), handler)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--server", default="127.0.0.1:50051", help="host:port of the server")
    add_security_arguments(parser)
    parser.add_argument("--session", help="follow this session instead of the first one listed")
    parser.add_argument("--host", default="127.0.0.1",
                        help="HTTP bind address (default 127.0.0.1; 0.0.0.0 = every interface)")
    parser.add_argument("--port", type=int, default=8080, help="HTTP port (0 picks a free one)")
    parser.add_argument("--max-fps", type=float, default=0.0, help="0 = the session's rate")
    args = parser.parse_args(argv)

    frames = LatestFrames()
    once_log = OnceLog()
    client = DownpourClient(args.server, timeout_s=5.0, **security_options(args))
    follower = Follower(client, frames, args.session, args.max_fps, once_log)
    directory = SessionDirectory(client, frames, once_log, args.server)
    drive = DriveController(client, follower, once_log)
    httpd = make_server(frames, args.port, args.host, directory, follower, drive)
    if args.host not in ("127.0.0.1", "localhost", "::1"):
        log(f"warning: listening on {args.host}: whoever reaches this port sees the sessions and "
            f"may drive one with this viewer's token")
    signal.signal(signal.SIGTERM, lambda signum, frame: sys.exit(0))
    print(f"viewer: http://{args.host}:{httpd.server_address[1]}/ following "
          f"{args.session or 'the first session'} on {args.server}", flush=True)
    directory.start()
    follower.start()
    try:
        httpd.serve_forever()
    except (KeyboardInterrupt, SystemExit):
        pass
    finally:
        follower.stop()
        directory.stop()
        frames.close()
        drive.stop("the viewer exits")
        httpd.server_close()
        follower.join(timeout=5)
        client.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
