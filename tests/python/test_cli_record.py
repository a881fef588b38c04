"""The command line against the real server ($DOWNPOUR_SERVER): record (lockstep frames into MP4 and
MJPEG, counted by ffprobe), play's tick counts, watch and close; augment over a folder of pictures."""

import fresh_stubs  # noqa: F401  (first: the gRPC modules of the current contract)

import json
import os
import signal
import subprocess
import sys
import tempfile
import time
import unittest

from downpour_client import DownpourClient, view_spec
from server_process import SERVER, ServerProcess

REPO = fresh_stubs.REPO
CLIENT_ENV = dict(os.environ, PYTHONPATH=os.path.join(REPO, "clients", "python"))
FPS = 20
SCENARIO = {
    "name": "record_test", "duration_s": 2.0, "loop": True, "seed": 5, "fps": FPS,
    "views": [{"view": "COCKPIT", "width": 160, "height": 90},
              {"view": "ROAD", "width": 64, "height": 36},
              {"view": "WINDSHIELD", "width": 64, "height": 36},
              {"view": "RAIN", "width": 64, "height": 36}],
    "keyframes": [
        {"t": 0.0, "weather": {"rain_rate_mm_h": 20}, "wipers": {"mode": "LOW"},
         "vehicle": {"position_m": [0, 0, 0], "velocity_mps": [10, 0, 0]}},
        {"t": 2.0, "weather": {"rain_rate_mm_h": 40},
         "vehicle": {"position_m": [20, 0, 0], "velocity_mps": [10, 0, 0]}},
    ],
}


def setUpModule():
    if not SERVER:
        raise unittest.SkipTest("DOWNPOUR_SERVER is not set")


def count_frames(path):
    """The video frames ffprobe decodes in a file."""
    result = subprocess.run(
        ["ffprobe", "-v", "error", "-count_frames", "-select_streams", "v:0",
         "-show_entries", "stream=nb_read_frames,codec_name,width,height", "-of", "json", path],
        capture_output=True, text=True, timeout=60)
    if result.returncode != 0:
        raise AssertionError(f"ffprobe {path}: {result.stderr}")
    stream = json.loads(result.stdout)["streams"][0]
    return int(stream["nb_read_frames"]), stream["codec_name"], (stream["width"],
                                                                 stream["height"])


class CommandLineServerTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.folder = tempfile.TemporaryDirectory()
        cls.scenario_path = os.path.join(cls.folder.name, "scenario.json")
        with open(cls.scenario_path, "w") as file:
            json.dump(SCENARIO, file)
        cls.server = ServerProcess()
        try:
            cls.server.wait_started()
            cls.client = DownpourClient(cls.server.target)
            cls.client.wait_until_serving(30)
        except BaseException:
            cls.server.stop()
            raise

    @classmethod
    def tearDownClass(cls):
        cls.client.close()
        code, log = cls.server.stop()
        cls.folder.cleanup()
        if code != 0:
            raise AssertionError(f"server exited with {code}:\n{log}")

    def cli(self, *args, timeout=60):
        return subprocess.run(
            [sys.executable, "-m", "downpour_client", *args, "--server", self.server.target],
            env=CLIENT_ENV, capture_output=True, text=True, timeout=timeout)

    def path(self, name):
        return os.path.join(self.folder.name, name)

    def session_ids(self):
        return [s.session_id for s in self.client.list_sessions()]

    def check_jsonl(self, path, count, view, size):
        with open(path) as file:
            records = [json.loads(line) for line in file]
        self.assertEqual(len(records), count)
        numbers = [r["frame_number"] for r in records]
        self.assertEqual(numbers, sorted(set(numbers)))
        for index, record in enumerate(records):
            self.assertEqual(record["view"], view)
            self.assertEqual((record["width"], record["height"]), size)
            self.assertAlmostEqual(record["sim_time_s"], (index + 1) / FPS, places=6)
            self.assertGreater(record["jpeg_bytes"], 0)
            self.assertIn("render_ms", record["stats"])
            self.assertIn("glass_wet_fraction", record["stats"])
            self.assertEqual(set(record["stats"]["road_states"]), {"dry", "wet", "drench",
                                                                   "puddle"})
            self.assertEqual(len(record["tires"]), 4)
            self.assertEqual(record["ego_place"]["road_id"], "track")
        return records

    def test_record_mp4_has_exactly_the_frames_asked(self):
        out = self.path("cockpit.mp4")
        result = self.cli("record", self.scenario_path, "--out", out, "--frames", "20")
        self.assertEqual(result.returncode, 0, result.stderr)
        lines = result.stdout.splitlines()
        session_id = lines[0].split("=", 1)[1]
        self.assertRegex(lines[-1], r"^frames=20 images=20 .* view=COCKPIT size=160x90 ")
        frames, codec, size = count_frames(out)
        self.assertEqual((frames, size), (20, (160, 90)))
        self.assertIn(codec, ("h264", "mpeg4"))
        self.check_jsonl(self.path("cockpit.jsonl"), 20, "COCKPIT", (160, 90))
        self.assertNotIn(session_id, self.session_ids())

    def test_record_mjpeg_keeps_the_jpegs(self):
        out = self.path("road.mjpeg")
        stats = self.path("road-stats.jsonl")
        result = self.cli("record", self.scenario_path, "--out", out, "--duration", "1",
                          "--view", "ROAD", "--width", "96", "--height", "54", "--stats", stats)
        self.assertEqual(result.returncode, 0, result.stderr)
        frames, codec, size = count_frames(out)
        self.assertEqual((frames, codec, size), (20, "mjpeg", (96, 54)))
        records = self.check_jsonl(stats, 20, "ROAD", (96, 54))
        with open(out, "rb") as file:
            data = file.read()
        self.assertEqual(len(data), sum(r["jpeg_bytes"] for r in records))
        self.assertEqual(data.count(b"\xff\xd8\xff"), 20)

    def test_record_with_outputs_writes_matched_triplets(self):
        from PIL import Image
        out = self.path("truth.mjpeg")
        result = self.cli("record", self.scenario_path, "--out", out, "--frames", "6",
                          "--outputs", "clean,mask,depth")
        self.assertEqual(result.returncode, 0, result.stderr)
        truth = self.path("truth_frames")
        self.assertIn(f"truth={truth}", result.stdout)
        records = self.check_jsonl(self.path("truth.jsonl"), 6, "COCKPIT", (160, 90))
        for r in records:
            stem = f"{int(r['frame_number']):06d}"
            self.assertEqual(r["files"], {"jpeg": stem + ".jpg", "clean_jpeg": stem + "_clean.jpg",
                                          "water_mask_png": stem + "_mask.png",
                                          "depth_png": stem + "_depth.png"})
            for field, name in r["files"].items():
                self.assertEqual(os.path.getsize(os.path.join(truth, name)), r[field + "_bytes"])
        last = records[-1]["files"]
        with Image.open(os.path.join(truth, last["water_mask_png"])) as mask:
            self.assertEqual((mask.mode, mask.size), ("L", (160, 90)))
            self.assertGreater(mask.getextrema()[1], 8, "the rain and the glass's water show")
        with Image.open(os.path.join(truth, last["depth_png"])) as depth:
            self.assertEqual(depth.size, (160, 90))
            self.assertIn(depth.mode, ("I", "I;16", "I;16B"))
            self.assertEqual(depth.getextrema()[0], 0, "the sky")

    def test_record_closes_its_session_on_ctrl_c(self):
        out = self.path("interrupted.mp4")
        process = subprocess.Popen(
            [sys.executable, "-m", "downpour_client", "record", self.scenario_path, "--out", out,
             "--frames", "100000", "--server", self.server.target],
            env=CLIENT_ENV, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        try:
            session_id = process.stdout.readline().strip().split("=", 1)[1]
            deadline = time.monotonic() + 20
            while time.monotonic() < deadline:  # some frames recorded
                if os.path.exists(self.path("interrupted.jsonl")) and \
                        os.path.getsize(self.path("interrupted.jsonl")) > 2000:
                    break
                time.sleep(0.05)
            process.send_signal(signal.SIGINT)
            stdout, stderr = process.communicate(timeout=30)
        finally:
            process.kill()
        self.assertEqual(process.returncode, 0, stderr)
        recorded = int(stdout.split("frames=", 1)[1].split()[0])
        self.assertGreater(recorded, 0)
        self.assertEqual(count_frames(out)[0], recorded)  # a whole file, ended by ffmpeg
        self.assertNotIn(session_id, self.session_ids())

    def test_play_counts_ticks_not_views(self):
        lockstep = self.cli("play", self.scenario_path, "--frames", "5")
        self.assertEqual(lockstep.returncode, 0, lockstep.stderr)
        self.assertRegex(lockstep.stdout.splitlines()[-1], r"^frames=5 images=20 .*last_frame=5 ")
        # The sanitizer runs' server is slower (DOWNPOUR_TEST_TIME_SCALE): it gets longer.
        duration = 1.5 * float(os.environ.get("DOWNPOUR_TEST_TIME_SCALE", "1"))
        realtime = self.cli("play", self.scenario_path, "--mode", "realtime", "--duration",
                            str(duration))
        self.assertEqual(realtime.returncode, 0, realtime.stderr)
        summary = dict(item.split("=", 1) for item in realtime.stdout.splitlines()[-1].split())
        ticks, images = int(summary["frames"]), int(summary["images"])
        # 30 ticks of 4 views at 20 fps in 1.5 s: a tick is counted once, whatever its views
        # (a slow reader may get a tick without some of its views).
        self.assertGreater(ticks, 5)
        self.assertLessEqual(ticks, 20 * duration + 2)
        self.assertLessEqual(ticks, int(summary["last_frame"]))
        self.assertLessEqual(images, 4 * ticks)
        self.assertGreaterEqual(images, 3 * ticks)

    def test_watch_prints_a_line_per_tick_and_close_ends_it(self):
        info = self.client.create_session(
            [view_spec("COCKPIT", 64, 36), view_spec("RAIN", 48, 32)], mode="REALTIME", fps=10)
        out = self.path("watched")
        watched = self.cli("watch", info.session_id, "--frames", "3", "--out", out)
        self.assertEqual(watched.returncode, 0, watched.stderr)
        lines = watched.stdout.splitlines()
        self.assertEqual(len(lines), 3, watched.stdout)
        numbers = [int(line.split()[0].split("=")[1]) for line in lines]
        self.assertEqual(numbers, sorted(set(numbers)))
        for line in lines:
            self.assertRegex(line, r"^frame=\d+ sim_time_s=[0-9.]+ glass_wet=[0-9.]+ "
                                   r"drops_on_glass=\d+ COCKPIT:render_ms=[0-9.]+,.* RAIN:")
        self.assertEqual(sorted(os.listdir(out)),
                         sorted(f"{v}_{n:06d}.jpg" for v in ("cockpit", "rain") for n in numbers))
        as_json = self.cli("watch", info.session_id, "--views", "RAIN", "--frames", "2", "--json")
        self.assertEqual(as_json.returncode, 0, as_json.stderr)
        records = [json.loads(line) for line in as_json.stdout.splitlines()]
        self.assertEqual([r["view"] for r in records], ["RAIN", "RAIN"])

        # A watch that runs until the session ends: close ends it, as it ends the session.
        process = subprocess.Popen(
            [sys.executable, "-m", "downpour_client", "watch", info.session_id,
             "--server", self.server.target], env=CLIENT_ENV, stdout=subprocess.PIPE,
            stderr=subprocess.PIPE, text=True)
        try:
            first = process.stdout.readline()
            self.assertRegex(first, r"^frame=\d+ ")
            closed = self.cli("close", info.session_id)
            self.assertEqual(closed.returncode, 0, closed.stderr)
            self.assertEqual(closed.stdout.strip(), f"closed {info.session_id}")
            stdout, stderr = process.communicate(timeout=20)
        finally:
            process.kill()
        self.assertEqual(process.returncode, 0, stderr)
        self.assertNotIn(info.session_id, self.session_ids())
        again = self.cli("close", info.session_id)
        self.assertEqual(again.returncode, 1)
        self.assertIn("NOT_FOUND", again.stderr)

    # augment: rain and the wet glass over a folder of pictures (BACKGROUND_CLIENT).

    def test_augment_writes_a_rainy_frame_per_picture(self):
        from PIL import Image
        frames = self.path("pictures")
        os.makedirs(frames, exist_ok=True)
        for i, colour in enumerate([(200, 40, 30), (30, 40, 200), (40, 200, 30)]):
            Image.new("RGB", (160, 90), colour).save(os.path.join(frames, f"f{i}.png"))
        out = self.path("augmented")
        result = self.cli("augment", frames, out, "--rain", "30", "--speed", "20",
                          "--warmup", "0.5", "--fps", "10")
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(sorted(os.listdir(out)), ["f0.jpg", "f1.jpg", "f2.jpg", "stats.jsonl"])
        # Each frame is its picture with the rain over it: the picture's colour dominates.
        for i, channel in enumerate([0, 2, 1]):
            with Image.open(os.path.join(out, f"f{i}.jpg")) as image:
                self.assertEqual(image.size, (160, 90))
                means = [sum(band.getdata()) / (160 * 90) for band in image.convert("RGB").split()]
                self.assertEqual(max(range(3), key=lambda c: means[c]), channel, means)
        with open(os.path.join(out, "stats.jsonl")) as file:
            records = [json.loads(line) for line in file]
        self.assertEqual([r["picture"] for r in records], ["f0.png", "f1.png", "f2.png"])
        self.assertTrue(all(int(r["stats"].get("background_repeats", 0)) == 0 for r in records))
        self.assertTrue(all(r["stats"]["rain_streaks"] > 0 for r in records))
        self.assertEqual(self.session_ids(), [], "the session is closed")

    def test_augment_with_outputs_writes_the_clean_picture_and_the_mask(self):
        from PIL import Image
        frames = self.path("truth_pictures")
        os.makedirs(frames, exist_ok=True)
        Image.new("RGB", (160, 90), (90, 120, 160)).save(os.path.join(frames, "a.png"))
        out = self.path("truth_augmented")
        result = self.cli("augment", frames, out, "--rain", "30", "--warmup", "0.5", "--fps",
                          "10", "--outputs", "clean,mask", "--quality", "100")
        self.assertEqual(result.returncode, 0, result.stderr)
        self.assertEqual(sorted(os.listdir(out)),
                         ["a.jpg", "a_clean.jpg", "a_mask.png", "stats.jsonl"])
        with Image.open(os.path.join(out, "a_clean.jpg")) as clean:
            count, colour = max(clean.convert("RGB").getcolors(160 * 90))
        # The picture, one colour, without the water (the blades may cross it).
        self.assertGreater(count, 160 * 90 // 2)
        self.assertTrue(all(abs(c - level) <= 2 for c, level in zip(colour, (90, 120, 160))),
                        colour)
        with Image.open(os.path.join(out, "a_mask.png")) as mask:
            self.assertGreater(mask.getextrema()[1], 8)
        result = self.cli("augment", frames, self.path("depth_refused"), "--outputs", "depth")
        self.assertEqual(result.returncode, 1)
        self.assertIn("the client's own", result.stderr)

    def test_a_picture_of_another_size_is_refused(self):
        from PIL import Image
        frames = self.path("mixed")
        os.makedirs(frames, exist_ok=True)
        Image.new("RGB", (160, 90), (9, 9, 9)).save(os.path.join(frames, "a.png"))
        Image.new("RGB", (100, 90), (9, 9, 9)).save(os.path.join(frames, "b.png"))
        result = self.cli("augment", frames, self.path("mixed_out"))
        self.assertEqual(result.returncode, 1)
        self.assertIn("the PNG is 100x90, the view is 160x90", result.stderr)
        self.assertEqual(self.session_ids(), [], "the session is closed")


if __name__ == "__main__":
    unittest.main()
