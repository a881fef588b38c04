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
        session_id = self.create_session()
        status = self.wait_for(lambda s: len(s["views"]) == 2 and s["views"][0]["fps"] > 0)
        self.assertEqual(status["session_id"], session_id)
        self.assertEqual([(v["view"], v["width"], v["height"]) for v in status["views"]],
                         [("cockpit", 64, 48), ("rain", 32, 16)])

        code, content_type, page = self.get("/")
        self.assertEqual((code, content_type), (200, "text/html; charset=utf-8"))
        self.assertIn(b"/stream/", page)
        code, content_type, still = self.get("/frame/rain.jpg")
        self.assertEqual((code, content_type), (200, "image/jpeg"))
        self.assertEqual(Image.open(io.BytesIO(still)).size, (32, 16))
        self.assertEqual(self.get("/frame/road.jpg")[0], 404)

        connection = http.client.HTTPConnection("127.0.0.1", self.port, timeout=10)
        connection.request("GET", "/stream/cockpit")
        stream = connection.getresponse()
        self.assertTrue(stream.getheader("Content-Type").startswith("multipart/x-mixed-replace"))
        sizes = []
        for _ in range(3):
            headers = {}
            line = stream.fp.readline()
            while line.strip() != b"":
                key, _, value = line.decode().partition(":")
                headers[key.strip().lower()] = value.strip()
                line = stream.fp.readline()
            part = stream.fp.read(int(headers["content-length"]))
            self.assertEqual(headers["content-type"], "image/jpeg")
            sizes.append(Image.open(io.BytesIO(part)).size)
            stream.fp.readline()  # the CRLF after the part
        self.assertEqual(sizes, [(64, 48)] * 3)

        status = self.wait_for(lambda s: s["views"] and s["views"][0]["fps"] > 8)
        self.assertLess(status["views"][0]["fps"], 40)

        self.fake.CloseSession(pb.CloseSessionRequest(session_id=session_id), None)
        self.wait_for(lambda s: s["state"] == "waiting" and not s["views"])
        self.assertEqual(stream.fp.read(), b"")  # the MJPEG stream ends with its session

        second = self.create_session()
        status = self.wait_for(lambda s: s["session_id"] == second and s["views"])
        self.assertEqual(status["state"], "watching")

    def test_interrupt_stops_the_viewer(self):
        self.create_session()
        self.wait_for(lambda s: s["views"])
        self.viewer.send_signal(signal.SIGINT)
        self.assertEqual(self.viewer.wait(timeout=10), 0)


if __name__ == "__main__":
    unittest.main()
