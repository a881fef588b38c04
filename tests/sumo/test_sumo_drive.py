"""Eclipse SUMO drives a session of the real server in lockstep (ctest label sumo); and SUMO's
netconvert reads the built-in track's OpenDRIVE export.

The road is the same on both sides: the server has tests/data/maps/sumo_grid.xodr (a SUMO grid
converted to OpenDRIVE by netconvert) as a map, and SUMO runs on the network netconvert makes back
from that file. For 3 s at 320 x 180, the ego car stands for a second, then SUMO's driver model
takes it off along its lane among traffic (cars, a truck, a bus, a motorbike ahead).
"""

import io
import math
import os
import subprocess
import shutil
import sys
import tempfile
import unittest

from PIL import Image, ImageChops, ImageStat

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(REPO, "tests", "python"))
sys.path.insert(0, os.path.join(REPO, "clients", "sumo"))

from test_server import ServerProcessCase  # noqa: E402
from downpour.v1 import downpour_pb2 as pb  # noqa: E402
from downpour_sumo.bridge import SumoBridge, opendrive_to_sumo, run_lockstep  # noqa: E402

MAPS = os.path.join(REPO, "tests", "data", "maps")
STEP_S = 0.05
STAND_S = 1.0


def setUpModule():
    if not os.environ.get("DOWNPOUR_SERVER"):
        raise unittest.SkipTest("DOWNPOUR_SERVER is not set")
    for tool in ("sumo", "netconvert"):
        if shutil.which(tool) is None:
            raise AssertionError(f"{tool} is not installed (./downpour.sh installs sumo)")


def lower_half(jpeg):
    with Image.open(io.BytesIO(jpeg)) as image:
        image = image.convert("RGB")
        w, h = image.size
        return image.crop((0, h // 2, w, h))


def asphalt_share(image):
    pixels = list(image.getdata())
    grey = sum(1 for r, g, b in pixels if abs(r - g) < 14 and abs(g - b) < 14 and g < 150)
    return grey / len(pixels)


def mean_difference(a, b):
    return sum(ImageStat.Stat(ImageChops.difference(a, b)).mean) / 3.0


class SumoDriveTest(ServerProcessCase):
    SERVER_ARGS = ["--maps-dir", MAPS]

    def test_a_sumo_drive_in_lockstep(self):
        with tempfile.TemporaryDirectory() as folder:
            net = os.path.join(folder, "grid.net.xml")
            opendrive_to_sumo(os.path.join(MAPS, "sumo_grid.xodr"), net)
            with SumoBridge(net, step_s=STEP_S) as bridge:
                sumo = bridge.sumo
                for name, klass, length in (("truck", "truck", 12.0), ("bus", "bus", 12.0),
                                            ("moto", "motorcycle", 2.2)):
                    sumo.vehicletype.copy("DEFAULT_VEHTYPE", name)
                    sumo.vehicletype.setVehicleClass(name, klass)
                    sumo.vehicletype.setLength(name, length)
                # The street's inner lane (SUMO's lane 1, OpenDRIVE's -1), northbound.
                route = ["-90", "-93"]
                bridge.add_vehicle("ego", route, lane=1, depart_pos=20.0)
                bridge.add_vehicle("car1", route, lane=1, depart_pos=60.0, speed=8.0)
                bridge.add_vehicle("truck1", route, lane=0, depart_pos=45.0, speed=8.0,
                                   vtype="truck")
                bridge.add_vehicle("bus1", route, lane=0, depart_pos=90.0, speed=8.0,
                                   vtype="bus")
                bridge.add_vehicle("moto1", route, lane=1, depart_pos=100.0, speed=8.0,
                                   vtype="moto")
                bridge.step()
                sumo.vehicle.setSpeed("ego", 0.0)  # standing, until released
                weather = pb.Weather(sun_altitude_deg=40.0, cloudiness=0.3)
                info = self.client.create_session(
                    [("COCKPIT", 320, 180), ("ROAD", 320, 180)], mode="LOCKSTEP", seed=5,
                    initial=bridge.update(weather), roads={"map_name": "sumo_grid"},
                    ego=bridge.ego_vehicle())
                self.assertEqual(info.road_network, "map:sumo_grid")
                steps = []

                def on_step(update, frames):
                    steps.append((update, frames))
                    if bridge.time_s >= STAND_S:
                        sumo.vehicle.setSpeed("ego", -1.0)  # SUMO's model drives it

                run_lockstep(self.client, info.session_id, bridge, 3.0,
                             lambda t: (weather, None), on_step)
                self.client.close_session(info.session_id)

        self.assertEqual(len(steps), 60)
        classes = {t.vehicle_class for t in steps[0][0].traffic}
        self.assertEqual(classes, {pb.VEHICLE_CLASS_CAR, pb.VEHICLE_CLASS_TRUCK,
                                   pb.VEHICLE_CLASS_BUS, pb.VEHICLE_CLASS_MOTORBIKE})
        worst_offset = 0.0
        roads = []
        for k, (update, frames) in enumerate(steps, start=1):
            # In order, with exact sim times, every view of a step.
            self.assertEqual([f.view for f in frames], [pb.VIEW_COCKPIT, pb.VIEW_ROAD])
            for f in frames:
                self.assertEqual(f.frame_number, k)
                self.assertAlmostEqual(f.sim_time_s, k * STEP_S, delta=1e-9)
                self.assertAlmostEqual(f.client_time_s, update.sim_time_s, delta=1e-9)
            place = frames[0].ego_place
            self.assertEqual(place.lane_id, -1, f"step {k}: {place}")
            self.assertTrue(place.on_road)
            worst_offset = max(worst_offset, abs(place.lane_offset_m))
            roads.append(lower_half(frames[1].jpeg))
        # Standing (after the first frames' water settles), then driving.
        stand = [mean_difference(a, b) for a, b in zip(roads[4:18], roads[5:19])]
        drive = [mean_difference(a, b) for a, b in zip(roads[40:59], roads[41:60])]
        asphalt = [asphalt_share(image) for image in roads]
        travelled = steps[-1][0].vehicle.position_m.y - steps[0][0].vehicle.position_m.y
        print(f"\nlane offset at most {worst_offset:.3f} m; ROAD frames' mean change standing "
              f"{max(stand):.2f}, driving {min(drive):.2f}-{max(drive):.2f} (of 255); asphalt "
              f"{min(asphalt):.2f}-{max(asphalt):.2f} of the ground; travelled {travelled:.1f} m")
        self.assertLess(worst_offset, 0.2)
        self.assertGreater(travelled, 3.0)
        self.assertLess(max(stand), 0.5)
        self.assertGreater(min(drive), 2.0 * max(stand) + 0.3)
        self.assertGreater(min(asphalt), 0.4)


class ExportedTrackTest(unittest.TestCase):
    """The built-in track as OpenDRIVE (downpour-scenes --xodr), read by SUMO's netconvert: two
    lanes each way whose centres lie 1.75 and 5.25 m either side of the track's centreline."""

    def test_netconvert_reads_the_track(self):
        scenes = os.path.join(os.path.dirname(os.environ["DOWNPOUR_SERVER"]), "downpour-scenes")
        sys.path.append(os.path.join(os.environ.get("SUMO_HOME", "/usr/share/sumo"), "tools"))
        import sumolib  # noqa: E402
        with tempfile.TemporaryDirectory() as folder:
            xodr, net = os.path.join(folder, "track.xodr"), os.path.join(folder, "track.net.xml")
            subprocess.run([scenes, "--xodr", xodr], check=True, capture_output=True)
            opendrive_to_sumo(xodr, net)
            network = sumolib.net.readNet(net)

        def offset(x, y):  # from the centreline: straights at y 0 and 500, half circles of 250 m
            if 0.0 <= x <= 900.0:
                return min(abs(y), abs(y - 500.0))
            centre = (900.0, 250.0) if x > 900.0 else (0.0, 250.0)
            return abs(math.hypot(x - centre[0], y - centre[1]) - 250.0)

        offsets = []
        for edge in network.getEdges():
            if edge.getFunction() != "":
                continue
            self.assertEqual(len(edge.getLanes()), 2, edge.getID())
            for lane, expected in zip(edge.getLanes(), (5.25, 1.75)):  # SUMO's 0: the outer
                worst = max(abs(offset(x, y) - expected) for x, y in lane.getShape())
                offsets.append(worst)
                self.assertLess(worst, 0.05, f"lane {lane.getID()}")
        print(f"\n{len(offsets)} lanes, centres within {max(offsets) * 100:.1f} cm of the track's")
        self.assertEqual(len(offsets), 8)


if __name__ == "__main__":
    unittest.main()
