"""The thin viewer, run as its own process against the in-process fake server."""

import http.client
import io
import json
import os
import signal
import subprocess
import sys
import time
import unittest

from PIL import Image

import fake_server
from downpour_client import view_spec
from downpour.v1 import downpour_pb2 as pb

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
VIEWER = os.path.join(REPO, "clients", "viewer", "viewer.py")


def read_part(stream):
    """The next part of a multipart stream: (its headers, lower-cased; its body)."""
    headers = {}
    line = stream.fp.readline()
    while line.strip() != b"":
        key, _, value = line.decode().partition(":")
        headers[key.strip().lower()] = value.strip()
        line = stream.fp.readline()
    body = stream.fp.read(int(headers["content-length"]))
    stream.fp.readline()  # the CRLF after the part
    return headers, body


class ViewerTest(unittest.TestCase):
    def setUp(self):
        self.server, self.fake, target = fake_server.start()
        self.viewer = subprocess.Popen(
            [sys.executable, VIEWER, "--server", target, "--port", "0"],
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        banner = self.viewer.stdout.readline()
        self.port = int(banner.split("http://127.0.0.1:", 1)[1].split("/", 1)[0])

    def tearDown(self):
        if self.viewer.poll() is None:
            self.viewer.kill()
        self.viewer.communicate()
        self.server.stop(0)

    def get(self, path):
        connection = http.client.HTTPConnection("127.0.0.1", self.port, timeout=10)
        connection.request("GET", path)
        response = connection.getresponse()
        return response.status, response.getheader("Content-Type"), response.read()

    def status(self):
        return json.loads(self.get("/status.json")[2])

    def wait_for(self, condition, timeout_s=10.0):
        deadline = time.monotonic() + timeout_s
        status = None
        while time.monotonic() < deadline:
            status = self.status()
            if condition(status):
                return status
            time.sleep(0.1)
        self.fail(f"viewer never reached the expected state; last status {status}")

    def create_session(self):
        request = pb.CreateSessionRequest(
            views=[view_spec("COCKPIT", 64, 48), view_spec("RAIN", 32, 16)],
            mode=pb.MODE_REALTIME, fps=20)
        return self.fake.CreateSession(request, None).session_id

    def test_follows_a_session_and_serves_its_views(self):
        self.assertEqual(self.status()["state"], "waiting")
        self.assertEqual(self.get("/stream/cockpit")[0], 204)  # no session: no frame to wait for
        session_id = self.create_session()
        status = self.wait_for(lambda s: len(s["views"]) == 2 and s["views"][0]["fps"] > 0)
        self.assertEqual(status["session_id"], session_id)
        self.assertEqual([(v["view"], v["width"], v["height"]) for v in status["views"]],
                         [("cockpit", 64, 48), ("rain", 32, 16)])

        code, content_type, page = self.get("/")
        self.assertEqual((code, content_type), (200, "text/html; charset=utf-8"))
        self.assertIn(b"Downpour</span> control room", page)
        self.assertIn(b"/static/app.js", page)
        self.assertEqual(self.get("/static/app.js")[:2],
                         (200, "application/javascript; charset=utf-8"))
        self.assertEqual(self.get("/drive")[0], 200)
        self.assertEqual(self.get("/static/../viewer.py")[0], 404)
        self.assertEqual(self.get("/vendor/../viewer.py")[0], 404)
        code, content_type, still = self.get("/frame/rain.jpg")
        self.assertEqual((code, content_type), (200, "image/jpeg"))
        self.assertEqual(Image.open(io.BytesIO(still)).size, (32, 16))
        self.assertEqual(self.get("/frame/road.jpg")[0], 404)

        connection = http.client.HTTPConnection("127.0.0.1", self.port, timeout=10)
        connection.request("GET", "/stream/cockpit")
        stream = connection.getresponse()
        self.assertTrue(stream.getheader("Content-Type").startswith("multipart/x-mixed-replace"))
        sizes, numbers = [], []
        for _ in range(3):
            headers, part = read_part(stream)
            self.assertEqual(headers["content-type"], "image/jpeg")
            sizes.append(Image.open(io.BytesIO(part)).size)
            numbers.append(int(headers["x-frame-number"]))
            self.assertEqual(headers["x-view"], "cockpit")
        self.assertEqual(sizes, [(64, 48)] * 3)
        self.assertEqual(numbers, sorted(set(numbers)))  # each part a newer frame, numbered

        # A page's views on one connection: each view's parts, each named.
        both = http.client.HTTPConnection("127.0.0.1", self.port, timeout=10)
        both.request("GET", "/stream/cockpit,rain")
        parts = both.getresponse()
        seen = {}
        while len(seen) < 2 or min(len(n) for n in seen.values()) < 2:
            headers, part = read_part(parts)
            size = Image.open(io.BytesIO(part)).size
            self.assertEqual(size, {"cockpit": (64, 48), "rain": (32, 16)}[headers["x-view"]])
            seen.setdefault(headers["x-view"], []).append(int(headers["x-frame-number"]))
        for view, numbers in seen.items():
            self.assertEqual(numbers, sorted(set(numbers)), view)

        status = self.wait_for(lambda s: s["views"] and s["views"][0]["fps"] > 8)
        self.assertLess(status["views"][0]["fps"], 40)

        self.fake.CloseSession(pb.CloseSessionRequest(session_id=session_id), None)
        self.wait_for(lambda s: s["state"] == "waiting" and not s["views"])
        # The streams end with their session (read to the end: the parts written till then).
        for ending in (stream, parts):
            rest = ending.fp.read()
            self.assertTrue(rest == b"" or rest.endswith(b"\r\n"), rest[-40:])

        second = self.create_session()
        status = self.wait_for(lambda s: s["session_id"] == second and s["views"])
        self.assertEqual(status["state"], "watching")

    def post(self, path, body, headers=None):
        connection = http.client.HTTPConnection("127.0.0.1", self.port, timeout=10)
        data = body if isinstance(body, (bytes, str)) else json.dumps(body)
        connection.request("POST", path, data,
                           dict({"Content-Type": "application/json"}, **(headers or {})))
        response = connection.getresponse()
        raw = response.read()
        try:
            return response.status, json.loads(raw)
        except ValueError:
            return response.status, raw.decode(errors="replace")

    def test_only_its_own_pages_may_drive_it(self):
        start = {"width": 96, "height": 54}
        # Another site's page (the browser names it), and a name rebound to 127.0.0.1.
        for headers in ({"Origin": "http://evil.example"}, {"Sec-Fetch-Site": "cross-site"},
                        {"Host": "evil.example:8080"}):
            self.assertEqual(self.post("/api/drive/start", start, headers)[0], 403, headers)
        self.assertEqual(self.get("/status.json")[0], 200)
        self.assertEqual(self.fake.sessions, {})
        # Bodies that are too large, nested too deep, or of the wrong kind: 400, nothing started.
        self.assertEqual(self.post("/api/drive/controls", "[" * 30000 + "]" * 30000)[0], 400)
        self.assertEqual(self.post("/api/drive/start", b"x" * 70000)[0], 400)
        self.assertEqual(self.post("/api/drive/start", {"width": "wide"})[0], 400)
        self.assertEqual(json.loads(self.get("/api/drive/state.json")[2])["state"], "idle")
        # The page itself (same origin) may.
        code, drive = self.post("/api/drive/start", start,
                                {"Origin": f"http://127.0.0.1:{self.port}",
                                 "Sec-Fetch-Site": "same-origin"})
        self.assertEqual((code, drive["state"]), (200, "driving"))
        self.post("/api/drive/stop", {})

    def test_frame_stats_history_and_session_list(self):
        session_id = self.create_session()
        status = self.wait_for(lambda s: len(s["views"]) == 2 and s["sessions"])
        self.assertEqual(status["server"]["state"], "up")
        listed = status["sessions"][0]
        self.assertEqual((listed["session_id"], listed["mode"], listed["fps"]),
                         (session_id, "realtime", 20.0))
        self.assertEqual([v["view"] for v in listed["views"]], ["cockpit", "rain"])
        self.assertFalse(listed["late"])
        self.assertIn("glass_wet_fraction", status["views"][0]["stats"])

        connection = http.client.HTTPConnection("127.0.0.1", self.port, timeout=10)
        connection.request("GET", "/api/frame/cockpit.json")
        response = connection.getresponse()
        info = json.loads(response.read())
        self.assertEqual(response.status, 200)
        self.assertEqual((info["view"], info["width"], info["height"]), ("cockpit", 64, 48))
        for key in ("frame_number", "sim_time_s", "render_ms", "encode_ms", "latency_ms",
                    "view_wet_fraction", "road_states", "fps"):
            self.assertIn(key, info)
        self.assertEqual(self.get("/api/frame/road.json")[0], 404)

        # The page's frame loop: ?after=N answers with a newer frame.
        connection.request("GET", f"/frame/cockpit.jpg?after={info['frame_number']}")
        response = connection.getresponse()
        response.read()
        self.assertEqual(response.status, 200)
        self.assertGreater(int(response.getheader("X-Frame-Number")), info["frame_number"])

        time.sleep(0.6)
        history = json.loads(self.get("/api/history.json")[2])
        self.assertEqual(history["session_id"], session_id)
        self.assertGreaterEqual(len(history["views"]["cockpit"]["t"]), 2)
        self.assertEqual(set(history["views"]["cockpit"]),
                         {"t", "fps", "session_fps", "latency_ms", "render_ms", "encode_ms",
                          "glass_wet", "view_wet", "road_wet"})

        # Picking a session follows it.
        second = self.create_session()
        self.assertEqual(self.post("/api/follow", {"session_id": second})[0], 200)
        status = self.wait_for(lambda s: s["session_id"] == second and s["views"])
        self.assertEqual(status["selected"], second)

    def test_drive_it_yourself(self):
        code, drive = self.post("/api/drive/start", {"width": 96, "height": 54, "fps": 20})
        self.assertEqual((code, drive["state"]), (200, "driving"))
        session_id = drive["session_id"]
        info = self.fake.sessions[session_id]
        self.assertEqual(info.mode, pb.MODE_REALTIME)
        self.assertEqual([(v.view, v.width) for v in info.views],
                         [(pb.VIEW_COCKPIT, 96), (pb.VIEW_ROAD, 96)])
        self.wait_for(lambda s: s["session_id"] == session_id and s["views"])

        deadline = time.monotonic() + 2.0
        while time.monotonic() < deadline:  # the page repeats the held keys
            self.post("/api/drive/controls", {"throttle": True})
            time.sleep(0.2)
        code, drive = self.post("/api/drive/controls", {
            "throttle": False, "wipers": "high", "weather": {"rain_rate_mm_h": 75}})
        self.assertEqual(code, 200)
        self.assertGreater(drive["speed_mps"], 3.0)
        self.assertEqual(self.post("/api/drive/controls", {"wipers": "sideways"})[0], 400)
        self.assertEqual(self.post("/api/drive/controls", {"weather": {"hail": 1}})[0], 400)
        time.sleep(0.3)
        drive = json.loads(self.get("/api/drive/state.json")[2])
        self.assertEqual(drive["wipers_in_effect"], "high")
        self.assertEqual(drive["weather_in_effect"]["rain_rate_mm_h"], 75.0)

        updates = [u.update for u in list(self.fake.updates) if u.session_id == session_id]
        self.assertGreater(len(updates), 30)  # about 20 a second
        speeds = [u.vehicle.velocity_mps.x for u in updates]
        self.assertGreater(max(speeds), 3.0)
        self.assertTrue(all(u.HasField("vehicle") for u in updates))
        self.assertEqual([u.wipers.mode for u in updates if u.HasField("wipers")],
                         [pb.WIPER_HIGH])
        self.assertEqual([u.weather.rain_rate_mm_h for u in updates if u.HasField("weather")],
                         [75.0])
        # Along the track's first straight, in the outer lane.
        last = updates[-1].vehicle
        self.assertGreater(last.position_m.x, 20.0)
        self.assertAlmostEqual(last.position_m.y, -5.25, places=3)
        self.assertAlmostEqual(last.rotation.yaw_deg, 0.0, places=3)

        code, drive = self.post("/api/drive/stop", {})
        self.assertEqual((code, drive["state"]), (200, "ended"))
        self.assertNotIn(session_id, self.fake.sessions)

    def test_drive_session_closed_when_the_viewer_exits(self):
        session_id = self.post("/api/drive/start", {})[1]["session_id"]
        self.assertIn(session_id, self.fake.sessions)
        self.viewer.send_signal(signal.SIGTERM)
        self.assertEqual(self.viewer.wait(timeout=10), 0)
        self.assertNotIn(session_id, self.fake.sessions)

    def test_server_down_is_one_clean_line(self):
        self.server.stop(0).wait()
        status = self.wait_for(lambda s: s["server"]["state"] == "down")
        self.assertIn("unreachable", status["server"]["error"])
        time.sleep(2.5)  # a few retries
        self.viewer.send_signal(signal.SIGINT)
        self.viewer.wait(timeout=10)
        stderr = self.viewer.stderr.read()
        self.assertNotIn("Traceback", stderr)
        self.assertEqual(stderr.count("unreachable"), 1, stderr)
        self.assertEqual(len(stderr.strip().splitlines()), 1, stderr)

    def test_interrupt_stops_the_viewer(self):
        self.create_session()
        self.wait_for(lambda s: s["views"])
        self.viewer.send_signal(signal.SIGINT)
        self.assertEqual(self.viewer.wait(timeout=10), 0)


class TrackTest(unittest.TestCase):
    """The viewer's copy of the built-in track (server/sim/track.cpp) and its car."""

    @classmethod
    def setUpClass(cls):
        import importlib.util
        spec = importlib.util.spec_from_file_location("downpour_viewer", VIEWER)
        cls.viewer = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(cls.viewer)

    def test_track_geometry(self):
        track = self.viewer.Track()
        self.assertAlmostEqual(track.length, 2 * 900 + 2 * 3.141592653589793 * 250, places=6)
        x, y, z, heading, curvature, _ = track.at(900 + 3.141592653589793 * 250)
        self.assertAlmostEqual(x, 900, places=6)
        self.assertAlmostEqual(y, 500, places=6)
        self.assertAlmostEqual(heading, 3.141592653589793, places=6)
        self.assertEqual(curvature, 0.0)
        self.assertAlmostEqual(track.at(2 * 900 + 3.141592653589793 * 250 - 450)[2], 10.0)
        self.assertAlmostEqual(track.at(track.length + 5)[0], 5.0)

    def test_the_car_keeps_its_lane_through_the_curve_and_steers(self):
        car = self.viewer.Car(self.viewer.Track(), s=850.0, lateral=-5.25)
        car.speed = 20.0
        for _ in range(20 * 45):  # 45 s at 20 Hz, cruising, no keys: round the first curve
            car.step(0.05, False, False, 0.0)
            car.speed = 20.0
        self.assertGreater(car.s, 900 + 3.141592653589793 * 250)
        self.assertAlmostEqual(car.lateral, -5.25, delta=0.3)
        for _ in range(20):  # one second of left steering
            car.step(0.05, False, False, 1.0)
        self.assertGreater(car.lateral, -5.0)
        for _ in range(200):  # and a long hold stops at the road's edge
            car.step(0.05, False, False, 1.0)
        self.assertLessEqual(car.lateral, self.viewer.Track.PAVED_HALF_WIDTH)


if __name__ == "__main__":
    unittest.main()
