"""python3 -m downpour_carla: drive a Downpour session from a running CARLA server.

  python3 -m downpour_carla [--carla localhost:2000] [--server 127.0.0.1:50051] [--seconds 60]
      [--out /tmp/frames] [--overlay]

Spawns an ego vehicle on autopilot at the map's first spawn point (or takes --ego-id), runs CARLA
in synchronous mode and the session in lockstep on the CARLA map's roads. Needs the carla Python
package of the server's version; start the Downpour server with --max-message-mb 16 (a CARLA
map's OpenDRIVE is a few MiB). --overlay: COCKPIT is CARLA's own RGB and depth cameras at the
driver's eye (BACKGROUND_CLIENT), with Downpour's wet windshield, rain and spray over them; ROAD
stays Downpour's own world.
"""

import argparse
import sys

from downpour_client import (DownpourClient, add_security_arguments, security_options,
                             write_frames)

from .bridge import CarlaBridge, CarlaOverlay


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python3 -m downpour_carla", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--carla", default="localhost:2000")
    parser.add_argument("--server", default="127.0.0.1:50051")
    parser.add_argument("--ego-id", type=int, help="an existing vehicle actor's id")
    parser.add_argument("--seconds", type=float, default=60.0)
    parser.add_argument("--step", type=float, default=0.05)
    parser.add_argument("--size", default="640x360")
    parser.add_argument("--out", help="write the frames here")
    parser.add_argument("--overlay", action="store_true",
                        help="COCKPIT over CARLA's own camera pictures (with their depth)")
    add_security_arguments(parser)
    args = parser.parse_args(argv)
    import carla  # noqa: E402  (only where a CARLA server is)

    host, port = args.carla.rsplit(":", 1)
    carla_client = carla.Client(host, int(port))
    carla_client.set_timeout(20.0)
    world = carla_client.get_world()
    spawned = None
    if args.ego_id is not None:
        ego = world.get_actor(args.ego_id)
    else:
        blueprint = world.get_blueprint_library().filter("vehicle.*")[0]
        spawned = ego = world.spawn_actor(blueprint, world.get_map().get_spawn_points()[0])
        ego.set_autopilot(True)
    # The traffic manager's autopilots keep to CARLA's synchronous ticks.
    carla_client.get_trafficmanager().set_synchronous_mode(True)
    width, height = (int(v) for v in args.size.split("x"))
    bridge = CarlaBridge(world, ego)
    original = world.get_settings()
    overlay = None
    if args.overlay:
        overlay = CarlaOverlay(
            world, ego, bridge,
            lambda loc, rot: carla.Transform(carla.Location(*loc), carla.Rotation(*rot)),
            width=width, height=height)
    try:
        with DownpourClient(args.server, **security_options(args)) as client:
            cockpit = overlay.view_spec() if overlay else ("COCKPIT", width, height)
            info = bridge.create_session(client, [cockpit, ("ROAD", width, height)])
            print(f"session {info.session_id} on {info.road_network} ({info.roads} roads)")

            def save(update, frames):
                if args.out:
                    write_frames(args.out, frames)

            try:
                bridge.run_lockstep(client, info.session_id, args.seconds, args.step, save,
                                    overlay=overlay)
            finally:
                client.close_session(info.session_id)
    finally:
        if overlay is not None:
            overlay.destroy()
        world.apply_settings(original)
        if spawned is not None:
            spawned.destroy()
    return 0


if __name__ == "__main__":
    sys.exit(main())
