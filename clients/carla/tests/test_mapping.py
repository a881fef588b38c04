"""The CARLA mapping on numbers: frames and rotations through the axes' vectors, the pose's
reference point, weather and lamps."""

import math
import unittest

from downpour_carla import mapping


def downpour_axes(yaw, pitch, roll):
    """Downpour's forward, left and up vectors: the columns of Rz(yaw) Ry(pitch) Rx(roll)
    (server/sim/pose.cpp)."""
    y, p, r = (math.radians(v) for v in (yaw, pitch, roll))
    cy, sy, cp, sp, cr, sr = math.cos(y), math.sin(y), math.cos(p), math.sin(p), math.cos(r), math.sin(r)
    rz = [[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]]
    ry = [[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]]
    rx = [[1, 0, 0], [0, cr, -sr], [0, sr, cr]]
    mul = lambda a, b: [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
    m = mul(mul(rz, ry), rx)
    return tuple(tuple(m[i][j] for i in range(3)) for j in range(3))


class FramesTest(unittest.TestCase):
    def assertVec(self, a, b, places=9):
        for x, y in zip(a, b):
            self.assertAlmostEqual(x, y, places=places)

    def test_rotations_turn_the_same_axes(self):
        # Every rotator's forward, right and up, mirrored into Downpour's frame, are Downpour's
        # forward, -left and up for the mapped rotation.
        for pitch, yaw, roll in [(0, 0, 0), (0, 90, 0), (10, 0, 0), (0, 0, 15), (7, -130, 22),
                                 (-25, 300, -40)]:
            f, r, u = mapping.carla_axes(pitch, yaw, roll)
            df, dl, du = downpour_axes(*mapping.rotation_to_world(pitch, yaw, roll))
            self.assertVec(mapping.location_to_world(*f), df)
            self.assertVec(mapping.location_to_world(*r), tuple(-v for v in dl))
            self.assertVec(mapping.location_to_world(*u), du)

    def test_signs_in_words(self):
        # CARLA yaw 90 faces its +y (right): Downpour's -y, yaw -90.
        self.assertEqual(mapping.rotation_to_world(0, 90, 0), (-90, 0, 0))
        # Nose up in CARLA (pitch 10): forward climbs; Downpour's pitch is nose down positive.
        yaw, pitch, roll = mapping.rotation_to_world(10, 0, 0)
        self.assertGreater(downpour_axes(yaw, pitch, roll)[0][2], 0.0)
        self.assertEqual(pitch, -10)
        self.assertEqual(mapping.location_to_world(1.0, 2.0, 3.0), (1.0, -2.0, 3.0))

    def test_pose_is_the_ground_under_the_rear_axle(self):
        # A car at (100, 50, 0.3) facing CARLA's yaw 30, its rear wheels 1.4 m behind the actor,
        # 0.8 m either side, 0.35 m up with a 0.35 m radius.
        location, rotation = (100.0, 50.0, 0.3), (0.0, 30.0, 0.0)
        f, r, u = mapping.carla_axes(*rotation)
        wheel = lambda side: [100.0 * (l - 1.4 * fi + side * 0.8 * ri + 0.35 * ui)
                              for l, fi, ri, ui in zip(location, f, r, u)]
        local = mapping.rear_axle_local(location, rotation, [wheel(-1), wheel(1)], 0.35)
        self.assertVec(local, (-1.4, 0.0, 0.0))
        # Later the car has moved and turned: the reference point moves with it.
        position, (yaw, pitch, roll) = mapping.pose_from_carla((120.0, 40.0, 0.3), (0.0, -90.0, 0.0),
                                                              local)
        self.assertVec(position, (120.0, -(40.0 + 1.4), 0.3))
        self.assertEqual((yaw, pitch, roll), (90.0, -0.0, 0.0))

    def test_sizes_and_velocities(self):
        self.assertEqual(mapping.size_from_extent(2.3, 0.9, 0.75), (4.6, 1.8, 1.5))
        self.assertEqual(mapping.velocity_to_world(10.0, 3.0, -1.0), (10.0, -3.0, -1.0))


class WeatherTest(unittest.TestCase):
    def test_precipitation_curve(self):
        self.assertEqual(mapping.rain_mm_h(0), 0.0)
        self.assertAlmostEqual(mapping.rain_mm_h(100), 50.0)
        self.assertAlmostEqual(mapping.rain_mm_h(30), 3.82, places=2)   # SoftRain
        self.assertAlmostEqual(mapping.rain_mm_h(60), 13.2, places=1)   # MidRain
        self.assertAlmostEqual(mapping.rain_mm_h(10), 0.92, places=2)
        self.assertEqual(mapping.rain_mm_h(250), 50.0)
        rates = [mapping.rain_mm_h(p) for p in range(0, 101, 5)]
        self.assertEqual(rates, sorted(rates))

    def test_hard_rain_noon(self):
        # carla.WeatherParameters.HardRainNoon's values.
        w = mapping.weather_from_carla(cloudiness=100.0, precipitation=100.0, wind_intensity=100.0,
                                       sun_azimuth_angle=-1.0, sun_altitude_angle=45.0,
                                       fog_density=7.0)
        self.assertAlmostEqual(w["rain_rate_mm_h"], 50.0)
        self.assertEqual(w["cloudiness"], 1.0)
        self.assertAlmostEqual(w["fog_density"], 0.07)
        self.assertAlmostEqual(w["wind_speed_mps"], 20.0)
        self.assertEqual(w["sun_altitude_deg"], 45.0)
        self.assertAlmostEqual(w["sun_azimuth_deg"], 1.0)
        self.assertAlmostEqual(mapping.weather_from_carla(0, 0, 0, 270.0, -10.0, 0)["sun_azimuth_deg"],
                               90.0)


class LightsTest(unittest.TestCase):
    def test_flags(self):
        self.assertEqual(mapping.lights_from_carla(0)["headlights"], "OFF")
        self.assertEqual(mapping.lights_from_carla(mapping.LIGHT_POSITION | mapping.LIGHT_LOW_BEAM)
                         ["headlights"], "LOW")
        both = mapping.LIGHT_LOW_BEAM | mapping.LIGHT_HIGH_BEAM
        self.assertEqual(mapping.lights_from_carla(both)["headlights"], "HIGH")
        hazard = mapping.lights_from_carla(mapping.LIGHT_LEFT_BLINKER | mapping.LIGHT_RIGHT_BLINKER |
                                           mapping.LIGHT_BRAKE)
        self.assertTrue(hazard["left_indicator"] and hazard["right_indicator"] and hazard["brake"])
        self.assertFalse(hazard["reverse"])

    def test_classes(self):
        self.assertEqual(mapping.vehicle_class("truck"), "truck")
        self.assertEqual(mapping.vehicle_class("motorcycle", 2), "motorbike")
        self.assertEqual(mapping.vehicle_class("", 2), "motorbike")
        self.assertEqual(mapping.vehicle_class("van"), "car")


if __name__ == "__main__":
    unittest.main()
