"""The CARLA bridge against a stand-in for CARLA's Python API (no CARLA server here): what it
sends for a world, on numbers."""

import types
import unittest

import downpour_client  # noqa: F401  (puts the generated stubs on the path)
from downpour.v1 import downpour_pb2 as pb

from downpour_carla import mapping
from downpour_carla.bridge import CarlaBridge, CarlaOverlay

XODR = "<OpenDRIVE><header revMajor=\"1\" revMinor=\"4\"/></OpenDRIVE>"


def vec(x, y, z):
    return types.SimpleNamespace(x=x, y=y, z=z)


class Vehicle:
    def __init__(self, actor_id, location, yaw, base_type="car", extent=(2.3, 0.9, 0.75),
                 light_state=0):
        self.id = actor_id
        self.location, self.yaw = location, yaw
        self.attributes = {"base_type": base_type, "number_of_wheels": "4"}
        self.bounding_box = types.SimpleNamespace(extent=vec(*extent))
        self.light_state = light_state
        # Rear wheels 1.4 m behind the actor's origin, 0.8 m either side, 35 cm in radius, in
        # centimetres as CARLA gives them (the front two first).
        x, y, z = location
        wheel = lambda dx, dy: types.SimpleNamespace(
            position=vec((x + dx) * 100, (y + dy) * 100, (z + 0.35) * 100), radius=35.0)
        self.wheels = [wheel(1.3, -0.8), wheel(1.3, 0.8), wheel(-1.4, -0.8), wheel(-1.4, 0.8)]

    def get_transform(self):
        return types.SimpleNamespace(location=vec(*self.location),
                                     rotation=types.SimpleNamespace(pitch=0.0, yaw=self.yaw,
                                                                    roll=0.0))

    def get_velocity(self):
        return vec(5.0, 1.0, 0.0)

    def get_light_state(self):
        return self.light_state

    def get_physics_control(self):
        return types.SimpleNamespace(wheels=self.wheels)


class Actors(list):
    def filter(self, pattern):
        return Actors(a for a in self if pattern == "vehicle.*")


class World:
    def __init__(self, vehicles):
        self.vehicles = Actors(vehicles)
        self.settings = types.SimpleNamespace(synchronous_mode=False, fixed_delta_seconds=None)
        self.ticks = 0

    def get_map(self):
        return types.SimpleNamespace(to_opendrive=lambda: XODR)

    def get_weather(self):
        return types.SimpleNamespace(cloudiness=40.0, precipitation=60.0, wind_intensity=10.0,
                                     sun_azimuth_angle=30.0, sun_altitude_angle=15.0,
                                     fog_density=5.0)

    def get_actors(self):
        return self.vehicles

    def get_settings(self):
        return self.settings

    def apply_settings(self, settings):
        self.settings = settings

    def tick(self):
        self.ticks += 1
        for sensor in getattr(self, "sensors", []):
            sensor.shoot()

    def get_blueprint_library(self):
        return types.SimpleNamespace(find=lambda kind: Blueprint(kind))

    def spawn_actor(self, blueprint, transform, attach_to=None):
        sensor = Sensor(blueprint, transform, attach_to)
        self.sensors = getattr(self, "sensors", []) + [sensor]
        return sensor


class Blueprint:
    def __init__(self, kind):
        self.kind, self.attributes = kind, {}

    def set_attribute(self, name, value):
        self.attributes[name] = value


# What the stand-in's cameras see: CARLA's raw BGRA, a red picture and everything 10 m away
# (0.01 of the depth camera's 1000 m: 167772 in its 24-bit encoding).
RED_BGRA = bytes([30, 40, 200, 255])
TEN_M = 167772
TEN_M_BGRA = bytes([(TEN_M >> 16) & 0xff, (TEN_M >> 8) & 0xff, TEN_M & 0xff, 255])


class Sensor:
    def __init__(self, blueprint, transform, parent):
        self.blueprint, self.transform, self.parent = blueprint, transform, parent
        self.callback, self.destroyed = None, False

    def listen(self, callback):
        self.callback = callback

    def shoot(self):
        w = int(self.blueprint.attributes["image_size_x"])
        h = int(self.blueprint.attributes["image_size_y"])
        pixel = RED_BGRA if self.blueprint.kind.endswith("rgb") else TEN_M_BGRA
        self.callback(types.SimpleNamespace(width=w, height=h, raw_data=pixel * (w * h)))

    def stop(self):
        self.callback = None

    def destroy(self):
        self.destroyed = True


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
