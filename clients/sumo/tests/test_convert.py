"""SUMO's vehicle state in the contract's terms, on numbers (no SUMO needed)."""

import math
import unittest

from downpour_sumo import convert


class ConvertTest(unittest.TestCase):
    def test_compass_angles_become_yaws(self):
        # North is +y: yaw 90; east 0; south -90; west 180.
        self.assertAlmostEqual(convert.yaw_deg(0.0), 90.0)
        self.assertAlmostEqual(convert.yaw_deg(90.0), 0.0)
        self.assertAlmostEqual(convert.yaw_deg(180.0), -90.0)
        self.assertAlmostEqual(convert.yaw_deg(270.0), 180.0)
        self.assertAlmostEqual(convert.yaw_deg(315.0), 135.0)

    def test_the_front_bumper_becomes_the_rear_axle(self):
        # Heading north at 10 m/s, the front bumper at (5, 20, 1): the ego's rear axle 3.65 m
        # behind it, on a 5% climb (slope 2.86 degrees) a little lower too.
        position, rotation, velocity = convert.pose((5.0, 20.0, 1.0), 0.0, 0.0, 10.0,
                                                    convert.EGO_FRONT_BUMPER_M)
        self.assertAlmostEqual(position[0], 5.0)
        self.assertAlmostEqual(position[1], 20.0 - 3.65)
        self.assertAlmostEqual(position[2], 1.0)
        self.assertEqual(rotation, (90.0, -0.0, 0.0))
        self.assertAlmostEqual(velocity[0], 0.0)
        self.assertAlmostEqual(velocity[1], 10.0)
        slope = math.degrees(math.atan(0.05))
        position, rotation, velocity = convert.pose((0.0, 0.0, 0.0), 90.0, slope, 10.0, 3.65,
                                                    net_offset=(100.0, -50.0))
        self.assertAlmostEqual(position[0], -100.0 - 3.65 * math.cos(math.radians(slope)))
        self.assertAlmostEqual(position[1], 50.0)
        self.assertAlmostEqual(position[2], -3.65 * math.sin(math.radians(slope)))
        self.assertAlmostEqual(rotation[1], -slope, msg="uphill is nose up: pitch negative")
        self.assertAlmostEqual(velocity[2], 10.0 * math.sin(math.radians(slope)))

    def test_traffic_axles_follow_their_class_and_length(self):
        self.assertAlmostEqual(convert.traffic_front_to_rear_axle_m(convert.CAR, 4.6), 3.65)
        self.assertAlmostEqual(convert.traffic_front_to_rear_axle_m(convert.TRUCK, 12.0), 9.0)
        self.assertAlmostEqual(convert.traffic_front_to_rear_axle_m(convert.BUS, 24.0), 17.2)
        self.assertAlmostEqual(convert.traffic_front_to_rear_axle_m(convert.MOTORBIKE, 2.2), 1.75)
        self.assertEqual(convert.vehicle_class("passenger"), convert.CAR)
        self.assertEqual(convert.vehicle_class("trailer"), convert.TRUCK)
        self.assertEqual(convert.vehicle_class("coach"), convert.BUS)
        self.assertEqual(convert.vehicle_class("moped"), convert.MOTORBIKE)
        self.assertEqual(convert.vehicle_class("tram"), convert.CAR)

    def test_signals_become_lamps(self):
        self.assertEqual(convert.lights(0), {"headlights": convert.HEADLIGHTS_AUTO, "brake": False,
                                             "left_indicator": False, "right_indicator": False,
                                             "reverse": False})
        lamps = convert.lights(convert.SIGNAL_BRAKE | convert.SIGNAL_LEFT)
        self.assertTrue(lamps["brake"])
        self.assertTrue(lamps["left_indicator"])
        self.assertFalse(lamps["right_indicator"])
        hazard = convert.lights(convert.SIGNAL_EMERGENCY | convert.SIGNAL_HIGH_BEAM)
        self.assertTrue(hazard["left_indicator"] and hazard["right_indicator"])
        self.assertEqual(hazard["headlights"], convert.HEADLIGHTS_HIGH)
        self.assertEqual(convert.lights(convert.SIGNAL_FRONT)["headlights"],
                         convert.HEADLIGHTS_LOW)

    def test_net_offsets_and_ids(self):
        net = '<net>\n  <location netOffset="-12.50,300.00" convBoundary="0,0,1,1"/>\n</net>'
        self.assertEqual(convert.net_offset(net), (-12.5, 300.0))
        self.assertEqual(convert.net_offset("<net/>"), (0.0, 0.0))
        ids = convert.TrafficIds()
        self.assertEqual([ids("a"), ids("b"), ids("a"), ids("c")], [1, 2, 1, 3])


if __name__ == "__main__":
    unittest.main()
