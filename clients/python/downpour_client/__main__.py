"""Command line: play or record a scenario on a server, watch or close a session, list the sessions,
print the server's stats.

  downpour-client play SCENARIO.json [--mode lockstep|realtime] [--out DIR] [--frames N]
                       [--duration S] [--server HOST:PORT]
  downpour-client record SCENARIO.json --out FILE.mp4|.mov|.avi|.mkv|.mjpeg
                         [--frames N | --duration S] [--view COCKPIT] [--width W --height H]
  downpour-client watch SESSION_ID [--views COCKPIT ROAD] [--out DIR] [--frames N] [--json]
  downpour-client augment FRAMES_DIR OUT_DIR [--rain MM_H] [--speed MPS] [--wipers MODE]
                  [--outputs clean,mask]
                          [--depth-dir DIR] [--warmup S] [--fps F] [--fov DEG]
  downpour-client close SESSION_ID
  downpour-client list
  downpour-client stats

(or python3 -m downpour_client ...). The generated gRPC modules are imported once a command
runs: --help needs none.
"""

import argparse
import signal
import sys

from . import __version__
from .security import add_security_arguments


def _command(name):
    """The function of a command, imported when it runs (it needs the generated modules)."""
    def run(args):
        from . import commands
        return getattr(commands, name)(args)
    return run


def build_parser():
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("--server", default="127.0.0.1:50051", help="host:port of the server")
    add_security_arguments(common)
    common.add_argument("--wait-ready", type=float, default=0.0, metavar="S",
                        help="first wait up to S seconds for the server to report SERVING")
    parser = argparse.ArgumentParser(prog="downpour-client",
                                     description=__doc__.split("\n\n")[0].replace("\n", " "))
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")

    play_parser = commands.add_parser("play", parents=[common],
                                      help="create a session and play a scenario file on it")
    play_parser.add_argument("scenario", help="scenario JSON file")
    play_parser.add_argument("--mode", choices=("lockstep", "realtime"), default="lockstep")
    play_parser.add_argument("--out", help="save frames as DIR/<view>_<frame_number>.jpg")
    play_parser.add_argument("--frames", type=int, help="stop after N frames (ticks)")
    play_parser.add_argument("--duration", type=float, metavar="S",
                             help="stop after S seconds (lockstep: of scenario time)")
    play_parser.set_defaults(func=_command("play"))

    record_parser = commands.add_parser(
        "record", parents=[common],
        help="render a scenario frame by frame (lockstep) into a video file",
        description="Creates a lockstep session with one view, steps it once per frame at the "
                    "scenario's fps and writes the frames to a video: .mp4/.mov/.m4v encoded by "
                    "ffmpeg (H.264, else MPEG-4 part 2; yuv420p), .avi/.mkv with the JPEGs "
                    "as they are (ffmpeg -c copy), .mjpeg the JPEGs concatenated (no ffmpeg). "
                    "Each frame's stats go to a JSON line beside it (FILE.jsonl). The session "
                    "is closed at the end, also on Ctrl-C or an error.")
    record_parser.add_argument("scenario", help="scenario JSON file")
    record_parser.add_argument("--out", required=True, metavar="FILE",
                               help="the video file (its extension picks the format)")
    count = record_parser.add_mutually_exclusive_group()
    count.add_argument("--frames", type=int, help="record N frames")
    count.add_argument("--duration", type=float, metavar="S",
                       help="record S seconds of scenario time (default: the scenario's "
                            "duration_s)")
    record_parser.add_argument("--view", help="the view recorded (default: the scenario's first)")
    record_parser.add_argument("--width", type=int, help="the view's width (default: the "
                                                         "scenario's)")
    record_parser.add_argument("--height", type=int, help="the view's height")
    record_parser.add_argument("--codec", help="ffmpeg encoder of .mp4/.mov (default: libx264 "
                                               "if ffmpeg has it, else mpeg4)")
    record_parser.add_argument("--stats", metavar="FILE",
                               help="the JSON lines of the frames' stats (default: the video's "
                                    "name with .jsonl)")
    record_parser.add_argument("--outputs", metavar="LIST",
                               help="ground truth with each frame, comma-separated: clean (the "
                                    "frame without the water), mask (how much the water changes "
                                    "each pixel), depth (centimetres, 16-bit PNG); each frame is "
                                    "then also written to --truth-dir as STEM.jpg beside "
                                    "STEM_clean.jpg, STEM_mask.png and STEM_depth.png, matched "
                                    "pixel for pixel, and its JSON line names them")
    record_parser.add_argument("--truth-dir", metavar="DIR",
                               help="where --outputs go (default: the video's name with _frames)")
    record_parser.set_defaults(func=_command("record"))

    watch_parser = commands.add_parser(
        "watch", parents=[common], help="print (and save) a session's frames as they come",
        description="Watches a session's frames (WatchFrames): one line per tick with its "
                    "frame number, sim time and stats (or with --json a JSON line per frame); "
                    "ends with the session, after --frames ticks, or on Ctrl-C.")
    watch_parser.add_argument("session_id", metavar="SESSION_ID")
    watch_parser.add_argument("--endpoint", metavar="HOST:PORT",
                              help="the server that holds the session (SessionInfo.endpoint, as "
                                   "list prints it), when --server names several")
    watch_parser.add_argument("--views", nargs="+", metavar="VIEW",
                              help="the views watched (default: every view of the session)")
    watch_parser.add_argument("--out", metavar="DIR",
                              help="save frames as DIR/<view>_<frame_number>.jpg")
    watch_parser.add_argument("--frames", type=int, metavar="N", help="stop after N ticks")
    watch_parser.add_argument("--max-fps", type=float, default=0.0,
                              help="at most this many ticks a second (0: the session's rate)")
    watch_parser.add_argument("--json", action="store_true",
                              help="a JSON line per frame instead of a line per tick")
    watch_parser.set_defaults(func=_command("watch"))

    augment_parser = commands.add_parser(
        "augment", parents=[common], help="rain and a wet windshield over a folder of pictures",
        description="Creates a lockstep session whose view draws over the client's pictures "
                    "(BACKGROUND_CLIENT) and steps it once per picture (name order; JPEG or PNG, "
                    "all of one size, which the view takes), writing each rainy frame as "
                    "OUT_DIR/<picture's name>.jpg and its stats as JSON lines "
                    "(OUT_DIR/stats.jsonl). A picture over 900 KiB is sent as a JPEG of quality 95.")
    augment_parser.add_argument("frames_dir", metavar="FRAMES_DIR")
    augment_parser.add_argument("out_dir", metavar="OUT_DIR")
    augment_parser.add_argument("--rain", type=float, default=20.0, metavar="MM_H",
                                help="rain rate (default 20 mm/h)")
    augment_parser.add_argument("--speed", type=float, default=25.0, metavar="MPS",
                                help="the car's speed (default 25 m/s)")
    augment_parser.add_argument("--wipers", default="LOW",
                                help="OFF, INTERMITTENT (every 4 s), LOW or HIGH (default LOW)")
    augment_parser.add_argument("--view", default="COCKPIT",
                                help="COCKPIT (rain and glass) or WINDSHIELD (the glass alone)")
    augment_parser.add_argument("--depth-dir", metavar="DIR",
                                help="a depth PNG per picture, in the same name order")
    augment_parser.add_argument("--depth-encoding", default="PNG16_CM",
                                help="PNG16_CM (16-bit grey, centimetres) or CARLA_RGB")
    augment_parser.add_argument("--fps", type=float, default=30.0,
                                help="pictures a second of simulated time (default 30)")
    augment_parser.add_argument("--warmup", type=float, default=0.0, metavar="S",
                                help="seconds of rain over the first picture before the first "
                                     "frame (default 0)")
    augment_parser.add_argument("--fov", type=float, default=0.0, metavar="DEG",
                                help="the pictures' vertical field of view (default 60)")
    augment_parser.add_argument("--sun", type=float, default=35.0, metavar="DEG",
                                help="the sun's altitude (default 35)")
    augment_parser.add_argument("--cloudiness", type=float, default=0.8)
    augment_parser.add_argument("--seed", type=int, default=1)
    augment_parser.add_argument("--quality", type=int, default=92, help="JPEG quality of the "
                                                                        "frames")
    augment_parser.add_argument("--outputs", metavar="LIST",
                                help="ground truth beside each frame, comma-separated: clean "
                                     "(NAME_clean.jpg, the picture without the water), mask "
                                     "(NAME_mask.png, how much the water changes each pixel)")
    augment_parser.add_argument("--haze", action="store_true",
                                help="the server's haze (--fog, and the rain's) over the pictures "
                                     "by their depth, or the ground without one; their sky is "
                                     "left as it is")
    augment_parser.add_argument("--fog", type=float, default=0.0, metavar="DENSITY",
                                help="the weather's fog_density, 0 to 1 (default 0)")
    augment_parser.set_defaults(func=_command("augment"))

    close_parser = commands.add_parser("close", parents=[common], help="close a session")
    close_parser.add_argument("session_id", metavar="SESSION_ID")
    close_parser.add_argument("--endpoint", metavar="HOST:PORT",
                              help="the server that holds the session, when --server names several")
    close_parser.set_defaults(func=_command("close"))

    commands.add_parser("list", parents=[common], help="list the server's sessions") \
        .set_defaults(func=_command("list_sessions"))
    commands.add_parser("stats", parents=[common], help="print the server's stats as JSON") \
        .set_defaults(func=_command("stats"))
    return parser


def _interrupt(signum, frame):
    raise KeyboardInterrupt


def main(argv=None):
    args = build_parser().parse_args(argv)
    signal.signal(signal.SIGTERM, _interrupt)
    import grpc
    try:
        return args.func(args)
    except KeyboardInterrupt:
        return 0
    except grpc.RpcError as error:
        print(f"error: {error.code().name}: {error.details()}", file=sys.stderr)
    except (ValueError, OSError, TimeoutError, ImportError, RuntimeError) as error:
        print(f"error: {error}", file=sys.stderr)
    return 1


if __name__ == "__main__":
    sys.exit(main())
