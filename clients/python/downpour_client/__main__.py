"""Command line: play a scenario on a server, list its sessions, print its stats.

  python3 -m downpour_client play SCENARIO.json [--mode lockstep|realtime] [--out DIR]
                                  [--frames N] [--duration S] [--server HOST:PORT]
  python3 -m downpour_client list
  python3 -m downpour_client stats
"""

import argparse
import os
import signal
import sys
import threading
import time

import grpc
from google.protobuf import json_format

from . import DownpourClient, Scenario, add_security_arguments, security_options
from .messages import enum_name
from downpour.v1 import downpour_pb2 as pb

# Lockstep: requests sent ahead of their responses, so that the server always has the next step.
MAX_IN_FLIGHT = 4


class Player:
    """Plays a scenario over one Drive stream and saves or counts the frames that come back."""

    def __init__(self, client, scenario, session_id, mode, out_dir=None, frames=None,
                 duration_s=None):
        self.client = client
        self.scenario = scenario
        self.session_id = session_id
        self.mode = mode
        self.out_dir = out_dir
        self.max_frames = frames
        self.duration_s = duration_s
        if frames is None and duration_s is None and not scenario.loop:
            self.duration_s = scenario.duration_s
        self.ticks = 0
        self.images = 0
        self.last_frame = None
        self.started = None
        self._stop = threading.Event()
        self._slots = threading.Semaphore(MAX_IN_FLIGHT)
        self._call = None

    def run(self):
        self.started = time.monotonic()
        if self.mode == "lockstep":
            self._run(self._lockstep_requests(self._lockstep_count()))
        else:
            self._run(self._realtime_requests())

    def stop(self):
        """Ends the stream; safe from any thread, and more than once."""
        self._stop.set()
        self._slots.release()  # wakes a request generator waiting for a slot
        if self._call is not None:
            self._call.cancel()

    def summary(self):
        elapsed = time.monotonic() - self.started if self.started else 0.0
        fps = self.ticks / elapsed if elapsed > 0 else 0.0
        last = self.last_frame.frame_number if self.last_frame else "none"
        sim_time = self.last_frame.sim_time_s if self.last_frame else 0.0
        return (f"frames={self.ticks} images={self.images} elapsed_s={elapsed:.2f} "
                f"fps={fps:.1f} last_frame={last} sim_time_s={sim_time:.3f}")

    def _run(self, requests):
        self._call = self.client.drive(requests)
        timer = None
        if self.mode == "realtime" and self.duration_s is not None:
            timer = threading.Timer(self.duration_s, self.stop)
            timer.daemon = True
            timer.start()
        try:
            for response in self._call:
                self._slots.release()
                if response.frames:
                    self._record(response.frames)
                if self.max_frames is not None and self.ticks >= self.max_frames:
                    break
        except grpc.RpcError as error:
            if not (self._stop.is_set() and error.code() == grpc.StatusCode.CANCELLED):
                raise
        finally:
            if timer is not None:
                timer.cancel()
            self.stop()

    def _lockstep_count(self):
        counts = []
        if self.max_frames is not None:
            counts.append(self.max_frames)
        if self.duration_s is not None:
            counts.append(max(1, round(self.duration_s * self.scenario.fps)))
        return min(counts) if counts else None

    def _lockstep_requests(self, count):
        dt = 1.0 / self.scenario.fps
        step = 0
        while count is None or step < count:
            self._slots.acquire()
            if self._stop.is_set():
                return
            step += 1
            yield pb.DriveRequest(session_id=self.session_id if step == 1 else "",
                                  update=self.scenario.at(step * dt), dt_s=dt)

    def _realtime_requests(self):
        period = 1.0 / self.scenario.fps
        tick = 0
        while True:
            behind = time.monotonic() - self.started
            tick = max(tick, int(behind / period))  # skip ticks missed while we were slow
            if self._stop.wait(max(0.0, tick * period - behind)):
                return
            yield pb.DriveRequest(session_id=self.session_id if tick == 0 else "",
                                  update=self.scenario.at(tick * period), dt_s=0.0)
            tick += 1

    def _record(self, frames):
        self.ticks += 1
        self.images += len(frames)
        self.last_frame = frames[0]
        if self.out_dir is None:
            return
        for frame in frames:
            name = f"{enum_name(pb.View, frame.view).lower()}_{frame.frame_number:06d}.jpg"
            with open(os.path.join(self.out_dir, name), "wb") as file:
                file.write(frame.jpeg)


def play(args):
    if args.frames is not None and args.frames < 1:
        raise ValueError("--frames: must be >= 1")
    if args.duration is not None and not args.duration > 0:
        raise ValueError("--duration: must be > 0")
    scenario = Scenario.load(args.scenario)
    if args.out:
        os.makedirs(args.out, exist_ok=True)
    with DownpourClient(args.server, **security_options(args)) as client:
        if args.wait_ready:
            client.wait_until_serving(args.wait_ready)
        info = client.create_session_from(scenario.create_request(args.mode.upper()))
        print(f"session_id={info.session_id}", flush=True)
        player = Player(client, scenario, info.session_id, args.mode, args.out, args.frames,
                        args.duration)

        # From here a signal ends the stream from another thread, and the player returns as from
        # any end: no exception is thrown into gRPC's code, wherever the main thread is.
        def stop_playing(signum, frame):
            threading.Thread(target=player.stop, daemon=True).start()

        signal.signal(signal.SIGTERM, stop_playing)
        signal.signal(signal.SIGINT, stop_playing)
        try:
            player.run()
        except KeyboardInterrupt:
            player.stop()
        finally:
            _ignore_signals()  # a second Ctrl-C must not skip closing the session
            try:
                client.close_session(info.session_id)
            except grpc.RpcError as error:
                print(f"warning: closing {info.session_id}: {error.code().name}: "
                      f"{error.details()}", file=sys.stderr)
            print(player.summary(), flush=True)
    return 0


def list_sessions(args):
    with DownpourClient(args.server, **security_options(args)) as client:
        if args.wait_ready:
            client.wait_until_serving(args.wait_ready)
        for session in client.list_sessions():
            views = ",".join(f"{enum_name(pb.View, v.view)}:{v.width}x{v.height}"
                             for v in session.views)
            print(f"{session.session_id} mode={enum_name(pb.Mode, session.mode)} "
                  f"fps={session.fps:g} seed={session.seed} views={views} "
                  f"frames={session.frames_rendered} sim_time_s={session.sim_time_s:.3f} "
                  f"achieved_fps={session.achieved_fps:.1f} frames_late={session.frames_late} "
                  f"idle_s={session.idle_s:.1f}")
    return 0


def stats(args):
    with DownpourClient(args.server, **security_options(args)) as client:
        if args.wait_ready:
            client.wait_until_serving(args.wait_ready)
        print(json_format.MessageToJson(client.get_stats(), preserving_proto_field_name=True,
                                        including_default_value_fields=True))
    return 0


def build_parser():
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("--server", default="127.0.0.1:50051", help="host:port of the server")
    add_security_arguments(common)
    common.add_argument("--wait-ready", type=float, default=0.0, metavar="S",
                        help="first wait up to S seconds for the server to report SERVING")
    parser = argparse.ArgumentParser(prog="downpour_client", description=__doc__.splitlines()[0])
    commands = parser.add_subparsers(dest="command", required=True)
    play_parser = commands.add_parser("play", parents=[common],
                                      help="create a session and play a scenario file on it")
    play_parser.add_argument("scenario", help="scenario JSON file")
    play_parser.add_argument("--mode", choices=("lockstep", "realtime"), default="lockstep")
    play_parser.add_argument("--out", help="save frames as DIR/<view>_<frame_number>.jpg")
    play_parser.add_argument("--frames", type=int, help="stop after N frames (ticks)")
    play_parser.add_argument("--duration", type=float, metavar="S",
                             help="stop after S seconds (lockstep: of scenario time)")
    play_parser.set_defaults(func=play)
    commands.add_parser("list", parents=[common], help="list the server's sessions") \
        .set_defaults(func=list_sessions)
    commands.add_parser("stats", parents=[common], help="print the server's stats as JSON") \
        .set_defaults(func=stats)
    return parser


def _interrupt(signum, frame):
    raise KeyboardInterrupt


def _ignore_signals():
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_IGN)


def main(argv=None):
    args = build_parser().parse_args(argv)
    signal.signal(signal.SIGTERM, _interrupt)
    try:
        return args.func(args)
    except KeyboardInterrupt:
        return 0
    except grpc.RpcError as error:
        print(f"error: {error.code().name}: {error.details()}", file=sys.stderr)
    except (ValueError, OSError, TimeoutError) as error:
        print(f"error: {error}", file=sys.stderr)
    return 1


if __name__ == "__main__":
    sys.exit(main())
