"""The client library and the command line, against the in-process fake server."""

import io
import json
import os
import signal
import subprocess
import sys
import tempfile
import time
import unittest

import grpc
from PIL import Image

import fake_server
from downpour_client import DownpourClient, view_spec
from downpour.v1 import downpour_pb2 as pb

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
CLIENT_ENV = dict(os.environ, PYTHONPATH=os.path.join(REPO, "clients", "python"))

SCENARIO = {
    "name": "cli_test", "duration_s": 2.0, "loop": False, "seed": 1, "fps": 20,
    "views": [{"view": "COCKPIT", "width": 48, "height": 32},
              {"view": "RAIN", "width": 32, "height": 24}],
    "keyframes": [
        {"t": 0.0, "weather": {"rain_rate_mm_h": 0}, "wipers": {"mode": "OFF"}},
        {"t": 2.0, "weather": {"rain_rate_mm_h": 40}},
    ],
}


class ClientTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.server, cls.fake, cls.target = fake_server.start()
        cls.client = DownpourClient(cls.target)
        cls.client.wait_until_serving(10)

    @classmethod
    def tearDownClass(cls):
        cls.client.close()
        cls.server.stop(0)

    def test_view_spec(self):
        spec = view_spec("cockpit", 640, 360, quality=85)
        self.assertEqual((spec.view, spec.width, spec.height, spec.jpeg_quality),
                         (pb.VIEW_COCKPIT, 640, 360, 85))
        self.assertFalse(spec.HasField("camera_position_m"))
        self.assertFalse(spec.HasField("focus_distance_m"))
        self.assertFalse(spec.HasField("aperture_mm"))
        dash = view_spec("COCKPIT", 64, 48, focus_distance_m=0.8, aperture_mm=0)
        self.assertEqual((dash.focus_distance_m, dash.aperture_mm), (0.8, 0.0))
        self.assertTrue(dash.HasField("aperture_mm"))  # 0 (a pinhole) is set, not left out
        road = view_spec("VIEW_ROAD", 16, 16, camera_position_m=(1, 2, 3))
        self.assertEqual((road.view, road.camera_position_m.z), (pb.VIEW_ROAD, 3.0))
        self.assertEqual(view_spec(42, 16, 16).view, 42)  # raw numbers pass unchecked
        with self.assertRaisesRegex(ValueError, "view: unknown value 'FRONT'"):
            view_spec("FRONT", 16, 16)

    def test_session_lifecycle(self):
        info = self.client.create_session([("COCKPIT", 48, 32), ("ROAD", 32, 16, 90)],
                                          mode="LOCKSTEP", seed=5)
        self.assertEqual((info.mode, info.seed, len(info.views)), (pb.MODE_LOCKSTEP, 5, 2))
        self.assertIn(info.session_id, [s.session_id for s in self.client.list_sessions()])
        frames = self.client.step(info.session_id, 0.05)
        self.assertEqual([f.view for f in frames], [pb.VIEW_COCKPIT, pb.VIEW_ROAD])
        self.assertEqual(Image.open(io.BytesIO(frames[1].jpeg)).size, (32, 16))
        self.assertEqual(self.client.step(info.session_id, 0.05)[0].frame_number,
                         frames[0].frame_number + 1)
        self.client.close_session(info.session_id)
        self.assertNotIn(info.session_id, [s.session_id for s in self.client.list_sessions()])
        with self.assertRaises(grpc.RpcError) as caught:
            self.client.step(info.session_id, 0.05)
        self.assertEqual(caught.exception.code(), grpc.StatusCode.NOT_FOUND)

    def test_wait_until_serving_times_out(self):
        with DownpourClient("127.0.0.1:1") as nobody:
            started = time.monotonic()
            with self.assertRaisesRegex(TimeoutError, "not SERVING"):
                nobody.wait_until_serving(0.5)
            self.assertLess(time.monotonic() - started, 3.0)


class CommandLineTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.server, cls.fake, cls.target = fake_server.start()
        cls.folder = tempfile.TemporaryDirectory()
        cls.scenario_path = cls.write_scenario("cli.json", SCENARIO)

    @classmethod
    def tearDownClass(cls):
        cls.server.stop(0)
        cls.folder.cleanup()

    @classmethod
    def write_scenario(cls, name, data):
        path = os.path.join(cls.folder.name, name)
        with open(path, "w") as file:
            json.dump(data, file)
        return path

    def cli(self, *args, **kwargs):
        return subprocess.run(
            [sys.executable, "-m", "downpour_client", *args, "--server", self.target],
            env=CLIENT_ENV, capture_output=True, text=True, timeout=30, **kwargs)

    def test_play_lockstep_saves_frames_and_closes_the_session(self):
        out = os.path.join(self.folder.name, "lockstep")
        before = len(self.fake.drive_requests)
        result = self.cli("play", self.scenario_path, "--frames", "6", "--out", out,
                          "--wait-ready", "10")
        self.assertEqual(result.returncode, 0, result.stderr)
        lines = result.stdout.splitlines()
        self.assertRegex(lines[0], r"^session_id=fake-\d+$")
        self.assertRegex(lines[-1], r"^frames=6 images=12 ")
        self.assertEqual(sorted(os.listdir(out)),
                         [f"{v}_{n:06d}.jpg" for v in ("cockpit", "rain") for n in range(1, 7)])
        with Image.open(os.path.join(out, "rain_000003.jpg")) as image:
            self.assertEqual(image.size, (32, 24))
        requests = self.fake.drive_requests[before:]
        self.assertEqual([r.dt_s for r in requests], [0.05] * 6)
        self.assertEqual([bool(r.session_id) for r in requests], [True] + [False] * 5)
        self.assertAlmostEqual(requests[3].update.sim_time_s, 0.2)
        self.assertAlmostEqual(requests[3].update.weather.rain_rate_mm_h, 4.0)
        self.assertEqual(requests[3].update.wipers.mode, pb.WIPER_OFF)
        self.assertFalse(requests[3].update.HasField("vehicle"))
        self.assertNotIn(lines[0][len("session_id="):], self.fake.sessions)

    def test_play_lockstep_duration_counts_scenario_time(self):
        result = self.cli("play", self.scenario_path, "--duration", "0.5")
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertRegex(result.stdout.splitlines()[-1], r"^frames=10 ")

    def test_play_realtime_by_wall_clock(self):
        before = len(self.fake.drive_requests)
        started = time.monotonic()
        result = self.cli("play", self.scenario_path, "--mode", "realtime", "--duration", "1")
        elapsed = time.monotonic() - started
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertGreater(elapsed, 1.0)
        frames = int(result.stdout.splitlines()[-1].split()[0].split("=")[1])
        self.assertGreater(frames, 5)
        self.assertLess(frames, 30)
        sent = [r.update.sim_time_s for r in self.fake.drive_requests[before:]]
        self.assertGreater(len(sent), 10)
        self.assertEqual(sent, sorted(sent))
        self.assertEqual([r.dt_s for r in self.fake.drive_requests[before:]], [0.0] * len(sent))

    def test_sigterm_closes_the_session(self):
        looping = self.write_scenario("loop.json", dict(SCENARIO, loop=True))
        process = subprocess.Popen(
            [sys.executable, "-m", "downpour_client", "play", looping, "--server", self.target],
            env=CLIENT_ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        try:
            session_id = process.stdout.readline().strip().split("=", 1)[1]
            time.sleep(0.3)
            self.assertIn(session_id, self.fake.sessions)
            process.send_signal(signal.SIGTERM)
            stdout, stderr = process.communicate(timeout=10)
        finally:
            process.kill()
        self.assertEqual(process.returncode, 0, stderr)
        self.assertRegex(stdout, r"frames=\d+ ")
        self.assertNotIn(session_id, self.fake.sessions)

    def test_list_and_stats(self):
        info = self.fake.CreateSession(
            pb.CreateSessionRequest(views=[view_spec("ROAD", 64, 48)], fps=12), None)
        try:
            listed = self.cli("list")
            self.assertEqual(listed.returncode, 0, listed.stderr)
            self.assertIn(f"{info.session_id} mode=UNSPECIFIED fps=12 seed=0 views=ROAD:64x48",
                          listed.stdout)
            stats = self.cli("stats")
            self.assertEqual(stats.returncode, 0, stats.stderr)
            self.assertEqual(json.loads(stats.stdout)["renderer"], "fake")
        finally:
            self.fake.sessions.pop(info.session_id)

    def test_bad_scenario_is_reported(self):
        bad = self.write_scenario("bad.json", dict(SCENARIO, fps="fast"))
        result = self.cli("play", bad)
        self.assertEqual(result.returncode, 1)
        self.assertIn("fps: must be a finite number", result.stderr)


if __name__ == "__main__":
    unittest.main()
