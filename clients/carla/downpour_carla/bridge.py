"""Drives a Downpour session from a CARLA server (0.9.x's Python API; not installed here: the
`world` and actors are whatever carla.Client gives, duck-typed).

- The session's roads: the CARLA map's own OpenDRIVE (world.get_map().to_opendrive()), sent inline.
  CARLA's maps are a few MiB of XML: start the server with --max-message-mb 16 or so.
- Each tick: the ego vehicle's pose (its rear axle's ground point, measured once from its rear
  wheels), velocity and lamps (its VehicleLightState); every other vehicle as traffic with its
  bounding box's size, its class from its blueprint's base_type and its lamps; CARLA's weather.
- Lockstep: CARLA in synchronous mode at a fixed delta; world.tick(), then one Step of the same
  length. mapping.py holds the conversions and their reasons.
- Overlay (CarlaOverlay): CARLA's own RGB and depth cameras, attached where a view's camera is,
  feed that view as its background (BACKGROUND_CLIENT): Downpour adds the water on the glass, the
  blades, the rain and the spray to CARLA's pictures.
"""

import io
import queue

from downpour.v1 import downpour_pb2 as pb

from . import mapping

_CLASSES = {"car": pb.VEHICLE_CLASS_CAR, "truck": pb.VEHICLE_CLASS_TRUCK,
            "bus": pb.VEHICLE_CLASS_BUS, "motorbike": pb.VEHICLE_CLASS_MOTORBIKE}
_HEADLIGHTS = {"OFF": pb.HEADLIGHTS_OFF, "LOW": pb.HEADLIGHTS_LOW, "HIGH": pb.HEADLIGHTS_HIGH}


def _xyz(v):
    return (v.x, v.y, v.z)


def _rotator(r):
    return (r.pitch, r.yaw, r.roll)


def road_network(world):
    """The CARLA map's roads as the contract's RoadNetwork (inline OpenDRIVE)."""
    return pb.RoadNetwork(opendrive_xml=world.get_map().to_opendrive())


def weather(world):
    w = world.get_weather()
    return pb.Weather(**mapping.weather_from_carla(
        w.cloudiness, w.precipitation, w.wind_intensity, w.sun_azimuth_angle,
        w.sun_altitude_angle, w.fog_density))


class CarlaBridge:
    """One CARLA world feeding one session. ego: the vehicle actor whose view the session
    renders."""

    def __init__(self, world, ego):
        self.world = world
        self.ego = ego
        self._axles = {}

    def _axle(self, actor):
        """The rear axle's ground point in the actor's frame, measured once (its rear wheels are
        the physics control's last two)."""
        if actor.id not in self._axles:
            transform = actor.get_transform()
            wheels = actor.get_physics_control().wheels
            rear = [(w.position.x, w.position.y, w.position.z) for w in wheels[-2:]]
            radius_m = wheels[-1].radius / 100.0  # centimetres
            self._axles[actor.id] = mapping.rear_axle_local(
                _xyz(transform.location), _rotator(transform.rotation), rear, radius_m)
        return self._axles[actor.id]

    def vehicle_state(self, actor):
        transform = actor.get_transform()
        position, rotation = mapping.pose_from_carla(
            _xyz(transform.location), _rotator(transform.rotation), self._axle(actor))
        state = pb.VehicleState()
        state.position_m.x, state.position_m.y, state.position_m.z = position
        state.rotation.yaw_deg, state.rotation.pitch_deg, state.rotation.roll_deg = rotation
        velocity = mapping.velocity_to_world(*_xyz(actor.get_velocity()))
        state.velocity_mps.x, state.velocity_mps.y, state.velocity_mps.z = velocity
        lamps = mapping.lights_from_carla(int(actor.get_light_state()))
        state.lights.headlights = _HEADLIGHTS[lamps["headlights"]]
        for key in ("brake", "left_indicator", "right_indicator", "reverse"):
            setattr(state.lights, key, lamps[key])
        return state

    def update(self, sim_time_s, max_traffic=64):
        """The contract's Update for the world as it is now: the ego vehicle, the other vehicles
        nearest it (the server takes 64) as traffic, the weather."""
        u = pb.Update(sim_time_s=sim_time_s, replace_traffic=True)
        u.vehicle.CopyFrom(self.vehicle_state(self.ego))
        u.weather.CopyFrom(weather(self.world))
        here = self.ego.get_transform().location

        def distance(actor):
            there = actor.get_transform().location
            return (there.x - here.x) ** 2 + (there.y - here.y) ** 2

        others = [a for a in self.world.get_actors().filter("vehicle.*") if a.id != self.ego.id]
        for actor in sorted(sorted(others, key=distance)[:max_traffic], key=lambda a: a.id):
            attributes = getattr(actor, "attributes", {})
            klass = mapping.vehicle_class(attributes.get("base_type", ""),
                                          int(attributes.get("number_of_wheels", 4)))
            t = u.traffic.add(id=actor.id, vehicle_class=_CLASSES[klass])
            t.state.CopyFrom(self.vehicle_state(actor))
            t.size_m.x, t.size_m.y, t.size_m.z = mapping.size_from_extent(
                *_xyz(actor.bounding_box.extent))
        return u

    def create_session(self, client, views, seed=0):
        """A lockstep session on the CARLA map's roads, starting where the world is."""
        return client.create_session(views, mode="LOCKSTEP", seed=seed, initial=self.update(0.0),
                                     roads=road_network(self.world))

    def run_lockstep(self, client, session_id, seconds, dt_s=0.05, on_step=None, overlay=None):
        """CARLA in synchronous mode at dt_s, each tick one Step; on_step(update, frames). With an
        overlay (CarlaOverlay), each Step carries its cameras' pictures of that tick."""
        settings = self.world.get_settings()
        settings.synchronous_mode = True
        settings.fixed_delta_seconds = dt_s
        self.world.apply_settings(settings)
        steps = int(round(seconds / dt_s))
        for k in range(1, steps + 1):
            self.world.tick()
            update = self.update(k * dt_s)
            if overlay is not None:
                update.client_images.append(overlay.picture())
            frames = client.step(session_id, dt_s, update)
            if on_step is not None:
                on_step(update, frames)
        return steps


DEFAULT_EYE = ((1.05, 0.37, 1.22), (0.0, 2.0, 0.0))  # the COCKPIT view's default camera


class CarlaOverlay:
    """CARLA's RGB and depth cameras attached to the ego vehicle at a view's camera pose (Downpour's
    vehicle frame; the driver's eye by default) with the view's size and vertical fov: each tick's
    pair of pictures as the view's ClientImage (the picture a JPEG, the depth a PNG in CARLA's own
    encoding, DEPTH_CARLA_RGB). transform(location, rotation) makes a carla.Transform (the carla
    module is the caller's: this file does not import it). Create the session's view with
    background BACKGROUND_CLIENT and the same pose and fov."""

    def __init__(self, world, ego, bridge, transform, view="COCKPIT", width=640, height=360,
                 fov_deg=60.0, pose=DEFAULT_EYE, quality=92):
        self.view, self.width, self.height, self.quality = view, width, height, quality
        location, rotation = mapping.camera_from_view(bridge._axle(ego), *pose)
        library = world.get_blueprint_library()
        self.sensors, self._queues = [], []
        for kind in ("sensor.camera.rgb", "sensor.camera.depth"):
            blueprint = library.find(kind)
            blueprint.set_attribute("image_size_x", str(width))
            blueprint.set_attribute("image_size_y", str(height))
            blueprint.set_attribute("fov", str(mapping.horizontal_fov_deg(fov_deg, width, height)))
            sensor = world.spawn_actor(blueprint, transform(location, rotation), attach_to=ego)
            pictures = queue.Queue()
            sensor.listen(pictures.put)
            self.sensors.append(sensor)
            self._queues.append(pictures)

    def _image(self, pictures, mode, kind, **options):
        """The newest picture a camera has given, as PNG or JPEG bytes (CARLA's raw_data is BGRA)."""
        from PIL import Image  # python3-pil
        image = pictures.get(timeout=10.0)
        while not pictures.empty():
            image = pictures.get_nowait()
        if (image.width, image.height) != (self.width, self.height):
            raise ValueError(f"CARLA gave a {image.width}x{image.height} picture for a "
                             f"{self.width}x{self.height} view")
        rgb = Image.frombuffer("RGBA", (image.width, image.height), bytes(image.raw_data), "raw",
                               "BGRA", 0, 1).convert(mode)
        out = io.BytesIO()
        rgb.save(out, kind, **options)
        return out.getvalue()

    def picture(self):
        """This tick's pictures (after world.tick()) as the view's ClientImage."""
        colour = self._image(self._queues[0], "RGB", "JPEG", quality=self.quality)
        depth = self._image(self._queues[1], "RGB", "PNG")
        return pb.ClientImage(view=pb.View.Value("VIEW_" + self.view), image=colour, depth=depth,
                              depth_encoding=pb.DEPTH_CARLA_RGB)

    def view_spec(self, fov_deg=60.0, pose=DEFAULT_EYE):
        """The session's ViewSpec for these cameras."""
        spec = pb.ViewSpec(view=pb.View.Value("VIEW_" + self.view), width=self.width,
                           height=self.height, fov_deg=fov_deg, background=pb.BACKGROUND_CLIENT)
        if pose is not DEFAULT_EYE:
            (spec.camera_position_m.x, spec.camera_position_m.y,
             spec.camera_position_m.z) = pose[0]
            (spec.camera_rotation.yaw_deg, spec.camera_rotation.pitch_deg,
             spec.camera_rotation.roll_deg) = pose[1]
        return spec

    def destroy(self):
        for sensor in self.sensors:
            sensor.stop()
            sensor.destroy()
