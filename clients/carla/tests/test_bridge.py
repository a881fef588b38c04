"""The CARLA bridge against a stand-in for CARLA's Python API (no CARLA server here): what it
sends for a world, on numbers."""

import unittest

import downpour_client  # noqa: F401  (puts the generated stubs on the path)
from downpour.v1 import downpour_pb2 as pb

from downpour_carla import mapping
from downpour_carla.bridge import CarlaBridge, CarlaOverlay

from .standin import TEN_M, XODR, Vehicle, World

class Client:
    def __init__(self):
        self.created, self.steps = None, []

    def create_session(self, views, mode, seed, initial, roads):
        self.created = (views, mode, initial, roads)
        return pb.SessionInfo(session_id="s1")

    def step(self, session_id, dt_s, update):
        self.steps.append((session_id, dt_s, update))
        return []


class BridgeTest(unittest.TestCase):
    def setUp(self):
        self.ego = Vehicle(7, (10.0, 5.0, 0.0), 0.0,
                           light_state=mapping.LIGHT_LOW_BEAM | mapping.LIGHT_BRAKE)
        self.truck = Vehicle(9, (40.0, 8.5, 0.0), 0.0, base_type="truck",
                             extent=(6.0, 1.25, 1.9))
        self.world = World([self.ego, self.truck])
        self.bridge = CarlaBridge(self.world, self.ego)

    def test_the_session_is_on_the_maps_roads_and_the_world_as_it_is(self):
        client = Client()
        info = self.bridge.create_session(client, [("COCKPIT", 320, 180)])
        self.assertEqual(info.session_id, "s1")
        views, mode, initial, roads = client.created
        self.assertEqual(mode, "LOCKSTEP")
        self.assertEqual(roads.opendrive_xml, XODR)
        # The ego car: its rear axle 1.4 m behind its origin, y mirrored; lamps and weather.
        self.assertAlmostEqual(initial.vehicle.position_m.x, 8.6)
        self.assertAlmostEqual(initial.vehicle.position_m.y, -5.0)
        self.assertAlmostEqual(initial.vehicle.position_m.z, 0.0)
        self.assertAlmostEqual(initial.vehicle.velocity_mps.y, -1.0)
        self.assertEqual(initial.vehicle.lights.headlights, pb.HEADLIGHTS_LOW)
        self.assertTrue(initial.vehicle.lights.brake)
        self.assertAlmostEqual(initial.weather.rain_rate_mm_h, mapping.rain_mm_h(60.0))
        self.assertAlmostEqual(initial.weather.cloudiness, 0.4)
        # The truck as traffic: its id, class and size.
        self.assertEqual(len(initial.traffic), 1)
        truck = initial.traffic[0]
        self.assertEqual(truck.id, 9)
        self.assertEqual(truck.vehicle_class, pb.VEHICLE_CLASS_TRUCK)
        self.assertEqual((truck.size_m.x, truck.size_m.y, truck.size_m.z), (12.0, 2.5, 3.8))
        self.assertAlmostEqual(truck.state.position_m.y, -8.5)
        self.assertEqual(truck.state.lights.headlights, pb.HEADLIGHTS_OFF)

    def test_the_axle_is_measured_once_and_moves_with_the_car(self):
        self.bridge.update(0.0)
        # Turned to CARLA's yaw 90 (right, towards CARLA's +y: Downpour's -y) and moved on; its
        # wheels' positions are not read again.
        self.ego.location, self.ego.yaw = (20.0, 5.0, 0.0), 90.0
        self.ego.wheels = None
        u = self.bridge.update(1.0)
        self.assertAlmostEqual(u.vehicle.position_m.x, 20.0)
        self.assertAlmostEqual(u.vehicle.position_m.y, -3.6)
        self.assertAlmostEqual(u.vehicle.rotation.yaw_deg, -90.0)

    def test_lockstep_ticks_carla_then_steps_the_session(self):
        client = Client()
        self.assertEqual(self.bridge.run_lockstep(client, "s1", 0.15, dt_s=0.05), 3)
        self.assertTrue(self.world.settings.synchronous_mode)
        self.assertEqual(self.world.settings.fixed_delta_seconds, 0.05)
        self.assertEqual(self.world.ticks, 3)
        self.assertEqual([round(u.sim_time_s, 9) for _, _, u in client.steps], [0.05, 0.1, 0.15])
        self.assertTrue(all(dt == 0.05 for _, dt, _ in client.steps))


class OverlayTest(unittest.TestCase):
    """CARLA's cameras at the view's camera feed the view's pictures, every Step."""

    def test_each_step_carries_the_cameras_pictures(self):
        import io
        from PIL import Image
        ego = Vehicle(7, (10.0, 5.0, 0.0), 0.0)
        world = World([ego])
        bridge = CarlaBridge(world, ego)
        overlay = CarlaOverlay(world, ego, bridge, lambda loc, rot: (loc, rot), width=320,
                               height=180)
        # At the driver's eye: 1.05 m ahead of the rear axle (1.4 m behind the origin), 0.37 m to
        # the left (CARLA's -y), 1.22 m up; pitched 2 degrees down (CARLA's -2); CARLA's fov is
        # horizontal.
        rgb, depth = world.sensors
        (x, y, z), (pitch, yaw, roll) = rgb.transform
        self.assertAlmostEqual(x, -1.4 + 1.05)
        self.assertAlmostEqual(y, -0.37)
        self.assertAlmostEqual(z, 1.22)
        self.assertEqual((pitch, yaw, roll), (-2.0, -0.0, 0.0))
        self.assertAlmostEqual(float(rgb.blueprint.attributes["fov"]), 91.49, places=1)
        self.assertIs(rgb.parent, ego)
        self.assertEqual(depth.blueprint.kind, "sensor.camera.depth")
        client = Client()
        bridge.run_lockstep(client, "s1", 0.1, dt_s=0.05, overlay=overlay)
        self.assertEqual(len(client.steps), 2)
        for _, _, update in client.steps:
            self.assertEqual(len(update.client_images), 1)
            picture = update.client_images[0]
            self.assertEqual(picture.view, pb.VIEW_COCKPIT)
            self.assertEqual(picture.depth_encoding, pb.DEPTH_CARLA_RGB)
            with Image.open(io.BytesIO(picture.image)) as image:
                self.assertEqual((image.format, image.size), ("JPEG", (320, 180)))
                r, g, b = image.convert("RGB").getpixel((160, 90))
                self.assertGreater(r, 180)
                self.assertLess(b, 60)
            with Image.open(io.BytesIO(picture.depth)) as image:
                self.assertEqual((image.format, image.size), ("PNG", (320, 180)))
                r, g, b = image.convert("RGB").getpixel((5, 5))
                self.assertEqual(r + 256 * g + 65536 * b, TEN_M)
        spec = overlay.view_spec()
        self.assertEqual(spec.background, pb.BACKGROUND_CLIENT)
        self.assertEqual((spec.width, spec.height), (320, 180))
        overlay.destroy()
        self.assertTrue(all(s.destroyed for s in world.sensors))


if __name__ == "__main__":
    unittest.main()
