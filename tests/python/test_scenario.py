"""Scenario files: parsing, validation and interpolation."""

import json
import math
import os
import tempfile
import unittest

from downpour_client import Scenario
from downpour.v1 import downpour_pb2 as pb


def scenario_data():
    """Vehicle keys at 0 and 5 s, weather at 0 and 4 s, wipers at 0, 5 and 8 s."""
    return {
        "name": "test", "description": "unit test", "duration_s": 10.0, "fps": 10, "seed": 3,
        "views": [{"view": "COCKPIT", "width": 160, "height": 90, "jpeg_quality": 80},
                  {"view": "ROAD", "width": 128, "height": 72}],
        "keyframes": [
            {"t": 0.0,
             "vehicle": {"position_m": [0, 0, 0], "rotation_deg": [170, 0, -4],
                         "velocity_mps": [10, 0, 0]},
             "wipers": {"mode": "LOW"},
             "weather": {"rain_rate_mm_h": 10, "fog_density": 0.2, "rain_streak_count": 100,
                         "sun_altitude_deg": 30}},
            {"t": 4.0,
             "weather": {"rain_rate_mm_h": 30, "fog_density": 0.6, "rain_streak_count": 201,
                         "sun_altitude_deg": 30}},
            {"t": 5.0,
             "vehicle": {"position_m": [50, 10, 0], "rotation_deg": [-170, 10, 4],
                         "velocity_mps": [10, 2, 0]},
             "wipers": {"mode": "INTERMITTENT", "interval_s": 3}},
            {"t": 8.0, "wipers": {"mode": "MANUAL", "blade_angle_deg": [30, 40]}},
        ],
    }


def position(update):
    p = update.vehicle.position_m
    return [p.x, p.y, p.z]


class InterpolationTest(unittest.TestCase):
    def setUp(self):
        self.scenario = Scenario(scenario_data())

    def test_header(self):
        s = self.scenario
        self.assertEqual((s.name, s.duration_s, s.fps, s.seed, s.loop),
                         ("test", 10.0, 10.0, 3, False))

    def test_values_at_keyframes(self):
        update = self.scenario.at(5.0)
        self.assertEqual(position(update), [50.0, 10.0, 0.0])
        self.assertEqual(update.vehicle.rotation.yaw_deg, -170.0)
        self.assertEqual(update.vehicle.velocity_mps.y, 2.0)
        self.assertEqual(update.sim_time_s, 5.0)
        self.assertEqual(self.scenario.at(4.0).weather.rain_rate_mm_h, 30.0)

    def test_linear_between_keyframes(self):
        update = self.scenario.at(2.5)
        for got, want in zip(position(update), [25.0, 5.0, 0.0]):
            self.assertAlmostEqual(got, want)
        self.assertAlmostEqual(update.vehicle.velocity_mps.y, 1.0)
        self.assertAlmostEqual(update.vehicle.rotation.pitch_deg, 5.0)
        self.assertAlmostEqual(update.vehicle.rotation.roll_deg, 0.0)
        weather = self.scenario.at(1.0).weather
        self.assertAlmostEqual(weather.rain_rate_mm_h, 15.0)
        self.assertAlmostEqual(weather.fog_density, 0.3)
        self.assertAlmostEqual(weather.sun_altitude_deg, 30.0)
        self.assertEqual(weather.rain_streak_count, 125)  # 100 + 101 * 0.25, rounded
        self.assertEqual(weather.wind_speed_mps, 0.0)     # left out of the file: its default, 0

    def test_yaw_takes_the_shortest_arc(self):
        # 170 -> -170 goes through 180 (20 degrees), not through 0 (340 degrees). As the server's
        # reader, the result is not wrapped: 185 is the direction -175.
        self.assertAlmostEqual(self.scenario.at(2.5).vehicle.rotation.yaw_deg, 180.0)
        self.assertAlmostEqual(self.scenario.at(1.25).vehicle.rotation.yaw_deg, 175.0)
        self.assertAlmostEqual(self.scenario.at(3.75).vehicle.rotation.yaw_deg, 185.0)

    def test_wipers_hold_until_the_next_keyframe(self):
        self.assertEqual(self.scenario.at(4.99).wipers.mode, pb.WIPER_LOW)
        at5 = self.scenario.at(5.0).wipers
        self.assertEqual((at5.mode, at5.interval_s), (pb.WIPER_INTERMITTENT, 3.0))
        self.assertEqual(self.scenario.at(7.9).wipers.mode, pb.WIPER_INTERMITTENT)
        manual = self.scenario.at(9.0).wipers
        self.assertEqual(manual.mode, pb.WIPER_MANUAL)
        self.assertEqual(list(manual.blade_angle_deg), [30.0, 40.0])
        self.assertEqual(manual.interval_s, 4.0)  # left out: 4 s, as the server reads it

    def test_hold_before_first_and_after_last(self):
        data = scenario_data()
        data["keyframes"][0].pop("weather")  # weather now starts at 4 s
        scenario = Scenario(data)
        self.assertEqual(scenario.at(1.0).weather.rain_rate_mm_h, 30.0)
        self.assertEqual(scenario.at(9.5).weather.rain_rate_mm_h, 30.0)
        self.assertEqual(position(scenario.at(9.5)), [50.0, 10.0, 0.0])
        self.assertEqual(position(scenario.at(25.0)), [50.0, 10.0, 0.0])  # no loop: held

    def test_absent_channels_are_not_set(self):
        data = scenario_data()
        data["keyframes"] = [{"t": 0.0, "weather": {"rain_rate_mm_h": 5}}]
        update = Scenario(data).at(3.0)
        self.assertTrue(update.HasField("weather"))
        self.assertFalse(update.HasField("vehicle"))
        self.assertFalse(update.HasField("wipers"))

    def test_loop_wraps_time(self):
        data = scenario_data()
        data["loop"] = True
        scenario = Scenario(data)
        wrapped = scenario.at(12.5)
        self.assertEqual(wrapped.sim_time_s, 12.5)  # the clock itself is not wrapped
        for got, want in zip(position(wrapped), [25.0, 5.0, 0.0]):
            self.assertAlmostEqual(got, want)
        self.assertEqual(scenario.at(29.0).wipers.mode, pb.WIPER_MANUAL)
        self.assertEqual(scenario.at(31.0).wipers.mode, pb.WIPER_LOW)

    def test_create_request(self):
        request = self.scenario.create_request("REALTIME")
        self.assertEqual(request.mode, pb.MODE_REALTIME)
        self.assertEqual((request.fps, request.seed), (10.0, 3))
        self.assertEqual([(v.view, v.width, v.height, v.jpeg_quality) for v in request.views],
                         [(pb.VIEW_COCKPIT, 160, 90, 80), (pb.VIEW_ROAD, 128, 72, 0)])
        self.assertEqual(request.initial, self.scenario.at(0.0))
        self.assertEqual(request.initial.weather.rain_rate_mm_h, 10.0)
        for view in request.views:  # no lens in the file: left unset, the view's own
            self.assertFalse(view.HasField("focus_distance_m"))
            self.assertFalse(view.HasField("aperture_mm"))

    def test_lens_per_view(self):
        data = scenario_data()
        data["views"][0].update(focus_distance_m=0.5, aperture_mm=0)
        data["views"][1].update(aperture_mm=8, exposure_s=0.004)
        cockpit, road = Scenario(data).create_request().views
        self.assertEqual((cockpit.focus_distance_m, cockpit.aperture_mm), (0.5, 0.0))
        self.assertTrue(cockpit.HasField("aperture_mm"))  # 0 is a pinhole, not absent
        self.assertFalse(cockpit.HasField("exposure_s"))
        self.assertFalse(road.HasField("focus_distance_m"))
        self.assertEqual((road.aperture_mm, road.exposure_s), (8.0, 0.004))

    def test_load_from_file(self):
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, "s.json")
            with open(path, "w") as file:
                json.dump(scenario_data(), file)
            self.assertEqual(Scenario.load(path).at(2.5), self.scenario.at(2.5))
            with open(path, "w") as file:
                file.write("{not json")
            with self.assertRaisesRegex(ValueError, "s.json"):
                Scenario.load(path)


class ValidationTest(unittest.TestCase):
    def assert_rejected(self, change, field):
        data = scenario_data()
        change(data)
        with self.assertRaises(ValueError) as caught:
            Scenario(data)
        self.assertIn(field, str(caught.exception))

    def test_top_level(self):
        self.assert_rejected(lambda d: d.pop("name"), "name")
        self.assert_rejected(lambda d: d.update(duration_s=0), "duration_s")
        self.assert_rejected(lambda d: d.update(fps=-1), "fps")
        self.assert_rejected(lambda d: d.update(seed=-2), "seed")
        self.assert_rejected(lambda d: d.update(loop="yes"), "loop")
        self.assert_rejected(lambda d: d.update(keyframes=[]), "keyframes")
        self.assert_rejected(lambda d: d.update(speed=3), "scenario.speed")

    def test_views(self):
        self.assert_rejected(lambda d: d.update(views=[]), "views")
        self.assert_rejected(lambda d: d["views"][1].update(view="FRONT"), "views[1].view")
        self.assert_rejected(lambda d: d["views"][1].update(view="COCKPIT"), "views[1].view")
        self.assert_rejected(lambda d: d["views"][0].update(width=0), "views[0].width")
        self.assert_rejected(lambda d: d["views"][0].update(height=9.5), "views[0].height")
        self.assert_rejected(lambda d: d["views"][0].update(jpeg_quality=101),
                             "views[0].jpeg_quality")
        for bad in (0.01, 20000, -1, math.nan, math.inf, "3", True):
            self.assert_rejected(lambda d: d["views"][1].update(focus_distance_m=bad),
                                 "views[1].focus_distance_m")
        for bad in (-0.5, 80, math.nan, -math.inf, None):
            self.assert_rejected(lambda d: d["views"][0].update(aperture_mm=bad),
                                 "views[0].aperture_mm")

    def test_keyframes(self):
        self.assert_rejected(lambda d: d["keyframes"][1].update(t=6.0), "keyframes[2].t")
        self.assert_rejected(lambda d: d["keyframes"][3].update(t=11.0), "keyframes[3].t")
        self.assert_rejected(lambda d: d["keyframes"][1].pop("t"), "keyframes[1].t")
        self.assert_rejected(lambda d: d["keyframes"][2]["wipers"].update(mode="FAST"),
                             "keyframes[2].wipers.mode")
        self.assert_rejected(lambda d: d["keyframes"][2]["wipers"].pop("mode"),
                             "keyframes[2].wipers.mode")
        self.assert_rejected(
            lambda d: d["keyframes"][0]["weather"].update(rain_rate_mm_h=math.nan),
            "keyframes[0].weather.rain_rate_mm_h")
        self.assert_rejected(lambda d: d["keyframes"][0]["weather"].update(rain_rate=3),
                             "keyframes[0].weather.rain_rate")
        self.assert_rejected(
            lambda d: d["keyframes"][0]["weather"].update(rain_streak_count=-1),
            "keyframes[0].weather.rain_streak_count")
        self.assert_rejected(
            lambda d: d["keyframes"][2]["vehicle"].update(position_m=[1, 2]),
            "keyframes[2].vehicle.position_m")
        self.assert_rejected(
            lambda d: d["keyframes"][2]["vehicle"].update(rotation_deg=[1, "2", 3]),
            "keyframes[2].vehicle.rotation_deg[1]")


if __name__ == "__main__":
    unittest.main()
