"""A stand-in for the parts of CARLA's Python API the bridge uses (no CARLA server here): vehicles,
a world that ticks, and cameras that give each tick's picture as CARLA's raw BGRA. Its cameras see
a flat red picture with everything 10 m away, unless the world is given pictures of its own."""

import types

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
    """pictures: None, or {"rgb": BGRA bytes, "depth": BGRA bytes in CARLA's depth encoding} that
    the cameras give (of their size); xodr: the map's OpenDRIVE."""

    def __init__(self, vehicles, pictures=None, xodr=XODR):
        self.vehicles = Actors(vehicles)
        self.pictures, self.xodr = pictures, xodr
        self.settings = types.SimpleNamespace(synchronous_mode=False, fixed_delta_seconds=None)
        self.ticks = 0

    def get_map(self):
        return types.SimpleNamespace(to_opendrive=lambda: self.xodr)

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
        sensor = Sensor(blueprint, transform, attach_to, self)
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
    def __init__(self, blueprint, transform, parent, world):
        self.blueprint, self.transform, self.parent, self.world = blueprint, transform, parent, world
        self.callback, self.destroyed = None, False

    def listen(self, callback):
        self.callback = callback

    def shoot(self):
        w = int(self.blueprint.attributes["image_size_x"])
        h = int(self.blueprint.attributes["image_size_y"])
        kind = "rgb" if self.blueprint.kind.endswith("rgb") else "depth"
        if self.world.pictures is not None:
            raw = self.world.pictures[kind]
        else:
            raw = (RED_BGRA if kind == "rgb" else TEN_M_BGRA) * (w * h)
        self.callback(types.SimpleNamespace(width=w, height=h, raw_data=raw))

    def stop(self):
        self.callback = None

    def destroy(self):
        self.destroyed = True
