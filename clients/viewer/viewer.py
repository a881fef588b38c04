"""Thin viewer: follows one Downpour session and serves its views to a browser.

  python3 clients/viewer/viewer.py --server 127.0.0.1:50051 [--session ID] --port 8080

Without --session it follows the first session the server lists, and waits for the next one when
that closes. One WatchFrames stream brings every view; the latest JPEG of each view is kept and
served at / (a page with every view), /stream/<view> (MJPEG), /frame/<view>.jpg and /status.json.
"""

import argparse
import collections
import json
import os
import signal
import sys
import threading
import time
from http import HTTPStatus
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python"))

import grpc  # noqa: E402
from downpour_client import (  # noqa: E402
    DownpourClient, add_security_arguments, enum_name, security_options)
from downpour.v1 import downpour_pb2 as pb  # noqa: E402

MIN_RATE_SPAN_S = 0.5
FPS_WINDOW_S = 2.0
RETRY_S = 0.5
BOUNDARY = "downpour-frame"


class LatestFrames:
    """The latest frame of each view of the followed session; readers wait on a Condition."""

    def __init__(self):
        self.condition = threading.Condition()
        self.session_id = ""
        self.generation = 0  # counts follow() calls, so that readers notice a new stream
        self.state = "waiting"
        self.error = ""
        self.closed = False
        self._frames = {}    # view name -> Frame; guarded by condition
        self._arrivals = {}  # view name -> deque of arrival times; guarded by condition

    def follow(self, session_id):
        with self.condition:
            self.session_id, self.state, self.error = session_id, "watching", ""
            self.generation += 1
            self._frames.clear()
            self._arrivals.clear()
            self.condition.notify_all()

    def unfollow(self, error=""):
        with self.condition:
            self.session_id, self.state, self.error = "", "waiting", error
            self._frames.clear()
            self._arrivals.clear()
            self.condition.notify_all()

    def put(self, frame):
        view = enum_name(pb.View, frame.view).lower()
        with self.condition:
            self._frames[view] = frame
            arrivals = self._arrivals.setdefault(view, collections.deque())
            arrivals.append(time.monotonic())
            self._trim(arrivals)
            self.condition.notify_all()

    def close(self):
        with self.condition:
            self.closed = True
            self.condition.notify_all()

    def latest(self, view):
        """(generation, the view's latest frame or None)."""
        with self.condition:
            return self.generation, self._frames.get(view)

    def wait_newer(self, view, generation, frame_number):
        """The view's next frame after frame_number; None once that stream or view is gone."""
        with self.condition:
            while True:
                frame = self._frames.get(view)
                if self.closed or self.generation != generation or (
                        frame is None and self.state != "watching"):
                    return None
                if frame is not None and frame.frame_number != frame_number:
                    return frame
                self.condition.wait()

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
                })
            return {"state": self.state, "session_id": self.session_id,
                    "generation": self.generation, "error": self.error, "views": views}

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


class Follower(threading.Thread):
    """Finds the session to follow and copies its frames into a LatestFrames."""

    def __init__(self, client, frames, session_id=None, max_fps=0.0):
        super().__init__(name="follower", daemon=True)
        self.client = client
        self.frames = frames
        self.session_id = session_id
        self.max_fps = max_fps
        self._stopping = threading.Event()
        self._lock = threading.Lock()
        self._call = None  # guarded by _lock

    def stop(self):
        self._stopping.set()
        with self._lock:
            if self._call is not None:
                self._call.cancel()

    def run(self):
        while not self._stopping.is_set():
            try:
                session_id = self.session_id or self._first_session()
                if session_id:
                    self._watch(session_id)
                    continue
            except grpc.RpcError as error:
                self.frames.unfollow(f"{error.code().name}: {error.details()}")
            self._stopping.wait(RETRY_S)

    def _first_session(self):
        sessions = self.client.list_sessions()
        return sessions[0].session_id if sessions else None

    def _watch(self, session_id):
        with self._lock:
            if self._stopping.is_set():
                return
            self._call = self.client.watch_frames(session_id, max_fps=self.max_fps)
        self.frames.follow(session_id)
        try:
            for frame in self._call:
                self.frames.put(frame)
            self.frames.unfollow()
        except grpc.RpcError as error:
            if not self._stopping.is_set():
                self.frames.unfollow(f"{error.code().name}: {error.details()}")
                self._stopping.wait(RETRY_S)
        finally:
            with self._lock:
                self._call = None


PAGE = """<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>Downpour viewer</title>
<style>
body { background: #111; color: #ddd; font: 14px sans-serif; margin: 16px; }
#views { display: flex; flex-wrap: wrap; gap: 16px; }
figure { margin: 0; } img { display: block; max-width: 100%; background: #000; }
figcaption { padding: 4px 0; font-family: monospace; }
</style></head>
<body><div id="state">connecting</div><div id="views"></div>
<script>
let shown = "";
async function poll() {
  try {
    const s = await (await fetch("/status.json", {cache: "no-store"})).json();
    document.getElementById("state").textContent = s.state === "watching"
        ? "session " + s.session_id : "waiting for a session " + s.error;
    const key = s.generation + ":" + s.views.map(v => v.view).join(",");
    const box = document.getElementById("views");
    if (key !== shown) {
      shown = key;
      box.innerHTML = s.views.map(v => '<figure><img src="/stream/' + v.view + "?g=" +
          s.generation + '"><figcaption id="c_' + v.view + '"></figcaption></figure>').join("");
    }
    for (const v of s.views) {
      const c = document.getElementById("c_" + v.view);
      if (c) c.textContent = v.view + "  frame " + v.frame_number + "  " + v.fps.toFixed(1) +
          " fps  " + v.width + "x" + v.height;
    }
  } catch (e) { document.getElementById("state").textContent = "viewer unreachable"; }
  setTimeout(poll, 1000);
}
poll();
</script></body></html>
"""


class ViewerHandler(BaseHTTPRequestHandler):
    frames = None  # LatestFrames, set by make_server

    def do_GET(self):
        path = self.path.split("?", 1)[0]
        if path == "/":
            self._send(HTTPStatus.OK, "text/html; charset=utf-8", PAGE.encode())
        elif path == "/status.json":
            self._send(HTTPStatus.OK, "application/json", json.dumps(self.frames.status()).encode())
        elif path.startswith("/frame/") and path.endswith(".jpg"):
            _, frame = self.frames.latest(path[len("/frame/"):-len(".jpg")].lower())
            if frame is None:
                self._send(HTTPStatus.NOT_FOUND, "text/plain", b"no frame for this view\n")
            else:
                self._send(HTTPStatus.OK, "image/jpeg", frame.jpeg)
        elif path.startswith("/stream/"):
            self._stream(path[len("/stream/"):].lower())
        else:
            self._send(HTTPStatus.NOT_FOUND, "text/plain", b"not found\n")

    def _stream(self, view):
        generation, frame = self.frames.latest(view)
        if frame is None:
            self._send(HTTPStatus.NOT_FOUND, "text/plain", b"no frame for this view\n")
            return
        self.send_response(HTTPStatus.OK)
        self.send_header("Content-Type", f"multipart/x-mixed-replace; boundary={BOUNDARY}")
        self.send_header("Cache-Control", "no-store")
        self.end_headers()
        try:
            while frame is not None:
                self.wfile.write(f"--{BOUNDARY}\r\nContent-Type: image/jpeg\r\n"
                                 f"Content-Length: {len(frame.jpeg)}\r\n\r\n".encode())
                self.wfile.write(frame.jpeg)
                self.wfile.write(b"\r\n")
                self.wfile.flush()
                frame = self.frames.wait_newer(view, generation, frame.frame_number)
        except (BrokenPipeError, ConnectionResetError):
            pass
        self.close_connection = True

    def _send(self, status, content_type, body):
        self.send_response(status)
        self.send_header("Content-Type", content_type)
        self.send_header("Content-Length", str(len(body)))
        self.send_header("Cache-Control", "no-store")
        self.end_headers()
        self.wfile.write(body)

    def log_message(self, format, *args):
        pass


def make_server(frames, port, host="127.0.0.1"):
    handler = type("BoundViewerHandler", (ViewerHandler,), {"frames": frames})
    server = ThreadingHTTPServer((host, port), handler)
    server.daemon_threads = True
    return server


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--server", default="127.0.0.1:50051", help="host:port of the server")
    add_security_arguments(parser)
    parser.add_argument("--session", help="follow this session instead of the first one listed")
    parser.add_argument("--port", type=int, default=8080, help="HTTP port on 127.0.0.1")
    parser.add_argument("--max-fps", type=float, default=0.0, help="0 = the session's rate")
    args = parser.parse_args(argv)

    frames = LatestFrames()
    client = DownpourClient(args.server, **security_options(args))
    follower = Follower(client, frames, args.session, args.max_fps)
    httpd = make_server(frames, args.port)
    signal.signal(signal.SIGTERM, lambda signum, frame: sys.exit(0))
    print(f"viewer: http://127.0.0.1:{httpd.server_address[1]}/ following "
          f"{args.session or 'the first session'} on {args.server}", flush=True)
    follower.start()
    try:
        httpd.serve_forever()
    except (KeyboardInterrupt, SystemExit):
        pass
    finally:
        follower.stop()
        frames.close()
        httpd.server_close()
        follower.join(timeout=5)
        client.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
