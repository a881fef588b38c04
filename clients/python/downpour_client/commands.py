"""The command line's commands (see __main__.py for their options). They need the generated
modules, so __main__ imports this module only once a command runs."""

import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time

import grpc
from downpour.v1 import downpour_pb2 as pb

from .client import DownpourClient
from .frames import frame_record, save_frame_files
from .messages import (client_image, enum_name, message_dict, output_values, to_view_spec,
                       view_value, wiper_mode_value)
from .scenario import Scenario
from .security import security_options

# Lockstep: requests sent ahead of their responses, so that the server always has the next step.
MAX_IN_FLIGHT = 4


class Player:
    """Plays a scenario over one Drive stream and saves or counts the frames that come back.

    A tick is a frame number: its views come in one DriveResponse, or (a realtime reader that fell
    behind) some of them; ticks counts distinct frame numbers, images every frame. on_frames, if
    given, is called with each response's frames.
    """

    def __init__(self, client, scenario, session_id, mode, out_dir=None, frames=None,
                 duration_s=None, on_frames=None):
        self.client = client
        self.scenario = scenario
        self.session_id = session_id
        self.mode = mode
        self.out_dir = out_dir
        self.max_frames = frames
        self.duration_s = duration_s
        self.on_frames = on_frames
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
            self._run(self._lockstep_requests(self.lockstep_count()))
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

    def lockstep_count(self):
        """The steps a lockstep run sends: --frames, --duration's in scenario time, or None (a
        looping scenario with neither: until stopped)."""
        counts = []
        if self.max_frames is not None:
            counts.append(self.max_frames)
        if self.duration_s is not None:
            counts.append(max(1, round(self.duration_s * self.scenario.fps)))
        return min(counts) if counts else None

    def _run(self, requests):
        self._call = self.client.drive(requests, session_id=self.session_id)
        if self._stop.is_set():  # stopped while the call was being made
            self._call.cancel()
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
        first = True  # the first request sent names the session, whichever tick it is
        while True:
            behind = time.monotonic() - self.started
            tick = max(tick, int(behind / period))  # skip ticks missed while we were slow
            if self._stop.wait(max(0.0, tick * period - behind)):
                return
            yield pb.DriveRequest(session_id=self.session_id if first else "",
                                  update=self.scenario.at(tick * period), dt_s=0.0)
            first = False
            tick += 1

    def _record(self, frames):
        for frame in frames:
            if self.last_frame is None or frame.frame_number > self.last_frame.frame_number:
                self.ticks += 1
                self.last_frame = frame
        self.images += len(frames)
        if self.on_frames is not None:
            self.on_frames(frames)
        if self.out_dir is not None:
            save_jpegs(self.out_dir, frames)


def save_jpegs(out_dir, frames):
    """Writes each frame as OUT_DIR/<view>_<frame number>.jpg."""
    for frame in frames:
        name = f"{enum_name(pb.View, frame.view).lower()}_{frame.frame_number:06d}.jpg"
        with open(os.path.join(out_dir, name), "wb") as file:
            file.write(frame.jpeg)


def _connect(args):
    client = DownpourClient(args.server, **security_options(args))
    if args.wait_ready:
        try:
            client.wait_until_serving(args.wait_ready)
        except BaseException:
            client.close()
            raise
    return client


def _on_signals(stop):
    """From here a signal calls stop() from another thread: no exception is thrown into gRPC's
    code, wherever the main thread is, and the command returns as from any end."""
    def handler(signum, frame):
        threading.Thread(target=stop, daemon=True).start()

    signal.signal(signal.SIGTERM, handler)
    signal.signal(signal.SIGINT, handler)


def ignore_signals():
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_IGN)


def _play_then_close(client, player, session_id):
    """Runs the player until its end, a signal or Ctrl-C, then closes the session."""
    _on_signals(player.stop)
    try:
        player.run()
    except KeyboardInterrupt:
        player.stop()
    finally:
        _close_quietly(client, session_id)


def _close_quietly(client, session_id):
    """Closes a session of ours at the end of a command; a failure is a warning."""
    ignore_signals()  # a second Ctrl-C must not skip closing the session
    try:
        client.close_session(session_id)
    except grpc.RpcError as error:
        print(f"warning: closing {session_id}: {error.code().name}: {error.details()}",
              file=sys.stderr)


def _check_counts(args):
    if args.frames is not None and args.frames < 1:
        raise ValueError("--frames: must be >= 1")
    if getattr(args, "duration", None) is not None and not args.duration > 0:
        raise ValueError("--duration: must be > 0")


def play(args):
    _check_counts(args)
    scenario = Scenario.load(args.scenario)
    if args.out:
        os.makedirs(args.out, exist_ok=True)
    with _connect(args) as client:
        info = client.create_session_from(scenario.create_request(args.mode.upper()))
        print(f"session_id={info.session_id}", flush=True)
        player = Player(client, scenario, info.session_id, args.mode, args.out, args.frames,
                        args.duration)
        try:
            _play_then_close(client, player, info.session_id)
        finally:
            print(player.summary(), flush=True)
    return 0


def list_sessions(args):
    with _connect(args) as client:
        for session in client.list_sessions():
            views = ",".join(f"{enum_name(pb.View, v.view)}:{v.width}x{v.height}"
                             for v in session.views)
            endpoint = getattr(session, "endpoint", "") or "-"
            print(f"{session.session_id} mode={enum_name(pb.Mode, session.mode)} "
                  f"fps={session.fps:g} seed={session.seed} views={views} "
                  f"frames={session.frames_rendered} sim_time_s={session.sim_time_s:.3f} "
                  f"achieved_fps={session.achieved_fps:.1f} frames_late={session.frames_late} "
                  f"idle_s={session.idle_s:.1f} endpoint={endpoint}")
    return 0


def stats(args):
    with _connect(args) as client:
        print(json.dumps(message_dict(client.get_stats()), indent=2))
    return 0


def _route(client, session_id, endpoint=None):
    """The session's SessionInfo if the server that holds it lists it (its endpoint remembered),
    else None. endpoint: where the session lives (SessionInfo.endpoint), when known; the server
    at --server is asked otherwise."""
    if endpoint:
        client.remember(session_id, endpoint)
        try:
            return next((s for s in client.list_sessions_at(endpoint)
                         if s.session_id == session_id), None)
        except grpc.RpcError:
            return None
    try:
        return client.find_session(session_id)
    except grpc.RpcError:
        return None  # the call that follows reports what is wrong


def close(args):
    with _connect(args) as client:
        _route(client, args.session_id, args.endpoint)
        client.close_session(args.session_id)
        print(f"closed {args.session_id}", flush=True)
    return 0


class TickGrouper:
    """WatchFrames sends one Frame a message; this gathers a tick's views (its frame number) and
    hands the tick on once every view expected is there, or a later tick begins."""

    def __init__(self, expected_views, on_tick):
        self.expected = expected_views  # None: unknown, a tick ends when the next begins
        self.on_tick = on_tick
        self.pending = []

    def add(self, frame):
        if self.pending and frame.frame_number != self.pending[0].frame_number:
            self.flush()
        self.pending.append(frame)
        if self.expected is not None and len(self.pending) >= self.expected:
            self.flush()

    def flush(self):
        if self.pending:
            tick, self.pending = self.pending, []
            self.on_tick(tick)


def tick_line(frames):
    """One line for a tick: its frame number, sim time, the glass, then each view's stats."""
    first = frames[0]
    parts = [f"frame={first.frame_number}", f"sim_time_s={first.sim_time_s:.3f}",
             f"glass_wet={first.stats.glass_wet_fraction:.3f}",
             f"drops_on_glass={first.stats.drops_on_glass}"]
    for f in frames:
        s = f.stats
        roads = s.road_states
        parts.append(
            f"{enum_name(pb.View, f.view)}:render_ms={s.render_ms:.1f},encode_ms={s.encode_ms:.1f},"
            f"latency_ms={s.latency_ms:.1f},view_wet={s.view_wet_fraction:.3f},"
            f"road_wet={roads.wet + roads.drench + roads.puddle:.3f},"
            f"visibility_m={s.visibility_m:.0f},dropped={s.frames_dropped},bytes={len(f.jpeg)}")
    return " ".join(parts)


def watch(args):
    if args.frames is not None and args.frames < 1:
        raise ValueError("--frames: must be >= 1")
    views = [view_value(v, "--views") for v in args.views or []]
    if args.out:
        os.makedirs(args.out, exist_ok=True)
    with _connect(args) as client:
        info = _route(client, args.session_id, args.endpoint)
        expected = len(views) if views else (len(info.views) if info is not None else None)
        call = client.watch_frames(args.session_id, views, args.max_fps)
        stopped = threading.Event()
        counts = {"ticks": 0, "images": 0}
        started = time.monotonic()

        def stop():
            stopped.set()
            call.cancel()

        def on_tick(frames):
            counts["ticks"] += 1
            counts["images"] += len(frames)
            if args.json:
                for frame in frames:
                    print(json.dumps(frame_record(frame), separators=(",", ":")))
            else:
                print(tick_line(frames))
            sys.stdout.flush()
            if args.out:
                save_jpegs(args.out, frames)

        grouper = TickGrouper(expected, on_tick)
        _on_signals(stop)
        try:
            for frame in call:
                grouper.add(frame)
                if args.frames is not None and counts["ticks"] >= args.frames:
                    stop()
                    break
            else:
                grouper.flush()  # the stream ended (the session closed): its last tick
        except grpc.RpcError as error:
            if not (stopped.is_set() and error.code() == grpc.StatusCode.CANCELLED):
                raise
        finally:
            ignore_signals()
            elapsed = time.monotonic() - started
            print(f"ticks={counts['ticks']} images={counts['images']} elapsed_s={elapsed:.2f}",
                  file=sys.stderr, flush=True)
    return 0


# Recording: the container by the file's extension.
ENCODED_SUFFIXES = (".mp4", ".mov", ".m4v")  # re-encoded: H.264 (else MPEG-4 part 2), yuv420p
COPIED_SUFFIXES = (".avi", ".mkv")          # the JPEGs as they are, in the container
RAW_SUFFIXES = (".mjpeg", ".mjpg")          # the JPEGs concatenated, no ffmpeg needed


def _ffmpeg_encoder(ffmpeg):
    """libx264 when this ffmpeg has it, else its own MPEG-4 part 2 encoder."""
    result = subprocess.run([ffmpeg, "-hide_banner", "-encoders"], capture_output=True,
                            text=True)
    return "libx264" if " libx264 " in result.stdout else "mpeg4"


class VideoWriter:
    """JPEG frames into a video file at a constant rate (see the *_SUFFIXES above)."""

    def __init__(self, path, fps, codec=None):
        suffix = os.path.splitext(path)[1].lower()
        self.path = path
        self.frames = 0
        self.codec = "copy"
        self._process = None
        self._errors = None
        if suffix in RAW_SUFFIXES:
            self._file = open(path, "wb")
            return
        if suffix not in ENCODED_SUFFIXES + COPIED_SUFFIXES:
            raise ValueError(f"--out: unknown format {suffix or path!r}, expected one of "
                             + ", ".join(ENCODED_SUFFIXES + COPIED_SUFFIXES + RAW_SUFFIXES))
        ffmpeg = shutil.which("ffmpeg")
        if ffmpeg is None:
            raise ValueError(f"--out {path}: ffmpeg not found (Debian: apt-get install ffmpeg); "
                             "a .mjpeg file needs none")
        command = [ffmpeg, "-hide_banner", "-loglevel", "error", "-y",
                   "-f", "image2pipe", "-framerate", format(fps, ".10g"), "-c:v", "mjpeg",
                   "-i", "pipe:0"]
        if suffix in COPIED_SUFFIXES:
            command += ["-c:v", "copy"]
        else:
            self.codec = codec or _ffmpeg_encoder(ffmpeg)
            # yuv420p (what players take) wants even sizes: pad an odd one by a pixel.
            command += ["-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2,format=yuv420p",
                        "-c:v", self.codec]
            if self.codec == "libx264":
                command += ["-preset", "veryfast", "-crf", "18"]
            elif self.codec == "mpeg4":
                command += ["-q:v", "2"]
            command += ["-movflags", "+faststart"]
        command.append(path)
        self._errors = tempfile.TemporaryFile()
        # Its own session: a Ctrl-C at the terminal reaches us alone, and we end the file.
        self._process = subprocess.Popen(command, stdin=subprocess.PIPE,
                                         stdout=subprocess.DEVNULL, stderr=self._errors,
                                         start_new_session=True)
        self._file = self._process.stdin

    def write(self, jpeg):
        try:
            self._file.write(jpeg)
            self.frames += 1
        except BrokenPipeError:
            raise RuntimeError(f"ffmpeg stopped: {self._ffmpeg_errors()}") from None

    def close(self):
        """Ends the file (ffmpeg writes its index); raises RuntimeError if ffmpeg failed. A file
        that got no frame is removed."""
        if self._process is not None and self.frames == 0:
            self._process.kill()  # ffmpeg would fail on an empty input
        try:
            self._file.close()
        except BrokenPipeError:
            pass
        try:
            if self.frames == 0:
                if self._process is not None:
                    self._process.wait()
                try:
                    os.remove(self.path)
                except OSError:
                    pass
                return
            if self._process is None:
                return
            try:
                code = self._process.wait(timeout=120)
            except subprocess.TimeoutExpired:
                self._process.kill()
                code = self._process.wait()
            if code != 0:
                raise RuntimeError(f"ffmpeg failed ({code}): {self._ffmpeg_errors()}")
        finally:
            if self._errors is not None:
                self._errors.close()

    def _ffmpeg_errors(self):
        self._errors.seek(0)
        return self._errors.read().decode(errors="replace").strip()[-2000:] or "no message"


def _record_view(scenario, args):
    """The recorded view's ViewSpec: the scenario's spec of --view (default its first view),
    resized by --width/--height; a view the scenario lacks takes the first view's size."""
    specs = [to_view_spec(v) for v in scenario.views]
    wanted = view_value(args.view, "--view") if args.view else specs[0].view
    spec = next((s for s in specs if s.view == wanted), None)
    if spec is None:
        spec = pb.ViewSpec(view=wanted, width=specs[0].width, height=specs[0].height)
    if args.width is not None:
        spec.width = args.width
    if args.height is not None:
        spec.height = args.height
    if args.outputs:
        del spec.outputs[:]
        spec.outputs.extend(output_values(args.outputs, "--outputs"))
    return spec


def record(args):
    _check_counts(args)
    scenario = Scenario.load(args.scenario)
    if args.frames is None and args.duration is None and scenario.loop:
        raise ValueError("a looping scenario needs --frames or --duration")
    spec = _record_view(scenario, args)
    request = scenario.create_request("LOCKSTEP")
    del request.views[:]
    request.views.append(spec)
    stats_path = args.stats or os.path.splitext(args.out)[0] + ".jsonl"
    if os.path.abspath(stats_path) == os.path.abspath(args.out):
        raise ValueError(f"--stats: {stats_path} is the video itself")
    out_dir = os.path.dirname(os.path.abspath(args.out))
    os.makedirs(out_dir, exist_ok=True)
    truth_dir = None
    if spec.outputs:
        truth_dir = args.truth_dir or os.path.splitext(args.out)[0] + "_frames"
        os.makedirs(truth_dir, exist_ok=True)
    with _connect(args) as client:
        video = VideoWriter(args.out, scenario.fps, args.codec)
        finished = False
        try:
            with open(stats_path, "w", encoding="utf-8", buffering=1) as stats_file:
                info = client.create_session_from(request)
                print(f"session_id={info.session_id}", flush=True)

                def on_frames(frames):
                    for frame in frames:
                        if frame.view == spec.view:
                            video.write(frame.jpeg)
                            line = frame_record(frame)
                            if truth_dir is not None:
                                line["files"] = save_frame_files(
                                    truth_dir, f"{frame.frame_number:06d}", frame)
                            stats_file.write(json.dumps(line, separators=(",", ":")) + "\n")

                player = Player(client, scenario, info.session_id, "lockstep",
                                frames=args.frames, duration_s=args.duration,
                                on_frames=on_frames)
                _play_then_close(client, player, info.session_id)
            finished = True
        finally:
            try:
                video.close()
            except RuntimeError as error:
                if finished:
                    raise
                print(f"warning: {args.out}: {error}", file=sys.stderr)
        print(f"{player.summary()} view={enum_name(pb.View, spec.view)} "
              f"size={spec.width}x{spec.height} codec={video.codec} out={args.out} "
              f"stats={stats_path}" + (f" truth={truth_dir}" if truth_dir else ""), flush=True)
    return 0


# A picture is sent as it is up to this size; a larger one (a PNG, as a rule) is sent as a JPEG of
# quality 95, under the server's default message limit of 1 MiB.
_PICTURE_BYTES = 900 * 1024
_PICTURE_SUFFIXES = (".jpg", ".jpeg", ".png")


def _picture_files(folder, what):
    names = sorted(n for n in os.listdir(folder) if n.lower().endswith(_PICTURE_SUFFIXES))
    if not names:
        raise ValueError(f"{what}: no .jpg, .jpeg or .png files in {folder}")
    return [os.path.join(folder, n) for n in names]


def _picture_size(path):
    from PIL import Image  # python3-pil
    with Image.open(path) as image:
        return image.size


def _picture_bytes(path):
    with open(path, "rb") as file:
        data = file.read()
    if len(data) <= _PICTURE_BYTES:
        return data
    import io
    from PIL import Image
    with Image.open(io.BytesIO(data)) as image:
        out = io.BytesIO()
        image.convert("RGB").save(out, "JPEG", quality=95)
        return out.getvalue()


def augment_update(sim_time_s, x_m, args, picture, depth=None):
    """The update of one augmented frame: the car at x_m along the built-in track's straight at
    --speed, the weather and wipers of the command line, and the frame's picture."""
    update = pb.Update(sim_time_s=sim_time_s)
    update.vehicle.position_m.x = x_m
    update.vehicle.position_m.y = -5.25
    update.vehicle.velocity_mps.x = args.speed
    update.weather.rain_rate_mm_h = args.rain
    update.weather.cloudiness = args.cloudiness
    update.weather.sun_altitude_deg = args.sun
    update.weather.fog_density = args.fog
    update.wipers.mode = wiper_mode_value(args.wipers, "--wipers")
    if args.wipers.upper().endswith("INTERMITTENT"):
        update.wipers.interval_s = 4.0
    update.client_images.append(client_image(args.view, picture, depth, args.depth_encoding))
    return update


def augment(args):
    """Rain over a folder of pictures: each picture, in name order, the background of one lockstep
    step of 1 / --fps s; the frames written beside their pictures' names, and their stats as JSON
    lines (stats.jsonl)."""
    pictures = _picture_files(args.frames_dir, "FRAMES_DIR")
    depths = _picture_files(args.depth_dir, "--depth-dir") if args.depth_dir else None
    if depths is not None and len(depths) != len(pictures):
        raise ValueError(f"--depth-dir: {len(depths)} depth files for {len(pictures)} pictures")
    if not args.fps > 0:
        raise ValueError("--fps: must be > 0")
    width, height = _picture_size(pictures[0])
    os.makedirs(args.out_dir, exist_ok=True)
    spec = pb.ViewSpec(view=view_value(args.view, "--view"), width=width, height=height,
                       jpeg_quality=args.quality, fov_deg=args.fov,
                       background=pb.BACKGROUND_CLIENT,
                       outputs=output_values(args.outputs, "--outputs"), haze=args.haze)
    dt = 1.0 / args.fps
    with _connect(args) as client:
        first = _picture_bytes(pictures[0])
        first_depth = open(depths[0], "rb").read() if depths else None
        info = client.create_session([spec], mode="LOCKSTEP", fps=args.fps, seed=args.seed,
                                     initial=augment_update(0.0, 0.0, args, first, first_depth))
        print(f"session_id={info.session_id} size={width}x{height}", flush=True)
        ignore_signals()
        t = 0.0
        try:
            # Rain on the glass before the first frame, over the first picture.
            for _ in range(int(round(args.warmup * args.fps))):
                t += dt
                client.step(info.session_id, dt, augment_update(t, args.speed * t, args, first,
                                                                first_depth))
            with open(os.path.join(args.out_dir, "stats.jsonl"), "w", encoding="utf-8") as stats:
                for i, path in enumerate(pictures):
                    depth = open(depths[i], "rb").read() if depths else None
                    t += dt
                    frames = client.step(info.session_id, dt, augment_update(
                        t, args.speed * t, args, _picture_bytes(path), depth))
                    frame = frames[0]
                    stem = os.path.splitext(os.path.basename(path))[0]
                    files = save_frame_files(args.out_dir, stem, frame)
                    record = frame_record(frame)
                    record["picture"] = os.path.basename(path)
                    record["files"] = files
                    stats.write(json.dumps(record, separators=(",", ":")) + "\n")
        finally:
            _close_quietly(client, info.session_id)
    print(f"{len(pictures)} frames in {args.out_dir}", flush=True)
    return 0
