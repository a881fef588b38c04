"""python3 -m downpour_sumo: drive a Downpour session from a SUMO run.

  python3 -m downpour_sumo --net city.net.xml --map city --ego-route=E1,E2,E3 [--seconds 60]
      [--scenario clients/scenarios/city_drizzle.json] [--realtime] [--server 127.0.0.1:50051]

--map names the session's roads in the server's --maps-dir (the same roads as --net: make one
from the other with netconvert); --xodr FILE sends them inline instead. Frames are written to
--out (lockstep) as JPEG files.
"""

import argparse
import sys

from downpour_client import (DownpourClient, Scenario, add_security_arguments, security_options,
                             write_frames)
from downpour.v1 import downpour_pb2 as pb

from .bridge import SumoBridge, run_lockstep, run_realtime, scenario_conditions


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python3 -m downpour_sumo", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--net", required=True, help="SUMO network (.net.xml)")
    roads = parser.add_mutually_exclusive_group(required=True)
    roads.add_argument("--map", help="the same roads as a map in the server's --maps-dir")
    roads.add_argument("--xodr", help="the same roads as an OpenDRIVE file, sent inline")
    parser.add_argument("--ego-route", required=True, type=lambda s: s.split(","),
                        help="the ego car's edges, by comma (--ego-route=-90,-93: SUMO's ids "
                             "from OpenDRIVE start with '-')")
    parser.add_argument("--ego-lane", type=int, default=0, help="SUMO lane index (0: rightmost)")
    parser.add_argument("--traffic", type=int, default=4,
                        help="other vehicles on the ego's route, ahead of it")
    parser.add_argument("--seconds", type=float, default=30.0)
    parser.add_argument("--step", type=float, default=0.05, help="SUMO's step (s)")
    parser.add_argument("--scenario", help="weather and wipers from a scenario file")
    parser.add_argument("--realtime", action="store_true")
    parser.add_argument("--server", default="127.0.0.1:50051")
    parser.add_argument("--size", default="640x360")
    parser.add_argument("--out", help="lockstep: write the frames here")
    add_security_arguments(parser)
    args = parser.parse_args(argv)

    width, height = (int(v) for v in args.size.split("x"))
    scenario = Scenario.load(args.scenario) if args.scenario else None
    conditions = ((lambda t: scenario_conditions(scenario, t)) if scenario else
                  (lambda t: (None, None)))
    if args.map:
        road_network = pb.RoadNetwork(map_name=args.map)
    else:
        with open(args.xodr, encoding="utf-8") as file:
            road_network = pb.RoadNetwork(opendrive_xml=file.read())
    with DownpourClient(args.server, **security_options(args)) as client, \
            SumoBridge(args.net, step_s=args.step) as bridge:
        bridge.add_vehicle("ego", args.ego_route, lane=args.ego_lane, speed=0.0)
        for k in range(args.traffic):
            bridge.add_vehicle(f"car{k}", args.ego_route, lane="free", depart_pos=25.0 * (k + 1))
        bridge.step()
        mode = "REALTIME" if args.realtime else "LOCKSTEP"
        info = client.create_session([("COCKPIT", width, height), ("ROAD", width, height)],
                                     mode=mode, initial=bridge.update(*conditions(0.0)),
                                     roads=road_network, ego=bridge.ego_vehicle())
        print(f"session {info.session_id} on {info.road_network} ({info.roads} roads)")
        try:
            if args.realtime:
                run_realtime(client, info.session_id, bridge, args.seconds, conditions)
            else:
                def save(update, frames):
                    if args.out:
                        write_frames(args.out, frames)
                    place = frames[0].ego_place
                    print(f"t {update.sim_time_s:6.2f} s  road {place.road_id} lane "
                          f"{place.lane_id} offset {place.lane_offset_m:+.2f} m")

                run_lockstep(client, info.session_id, bridge, args.seconds, conditions, save)
        finally:
            client.close_session(info.session_id)
    return 0


if __name__ == "__main__":
    sys.exit(main())
