"""Runs Eclipse SUMO through TraCI and feeds a Downpour session from it: the ego vehicle's pose,
velocity and lamps, every other vehicle as traffic (size, class, lamps), weather and wipers from
a scenario or fixed values; lockstep (one Step for each SUMO step) or realtime (one Update for
each SUMO step, paced by the wall clock).

The road is the same on both sides when SUMO's network and the session's OpenDRIVE come from one
another through netconvert (opendrive_to_sumo, sumo_to_opendrive)."""

import os
import subprocess
import sys
import time

from downpour.v1 import downpour_pb2 as pb

from . import convert

SUMO_HOME = os.environ.get("SUMO_HOME", "/usr/share/sumo")


def _import_traci():
    tools = os.path.join(SUMO_HOME, "tools")
    if tools not in sys.path:
        sys.path.append(tools)
    import traci  # noqa: E402  (SUMO's own package, from $SUMO_HOME/tools)
    return traci


def opendrive_to_sumo(xodr_path, net_path, netconvert="netconvert"):
    """A SUMO network from an OpenDRIVE file, in the file's own coordinates."""
    subprocess.run([netconvert, "--opendrive-files", xodr_path, "-o", net_path,
                    "--offset.disable-normalization", "true", "--no-warnings", "true"],
                   check=True, capture_output=True)


def sumo_to_opendrive(net_path, xodr_path, netconvert="netconvert"):
    """An OpenDRIVE file from a SUMO network (its coordinates less its netOffset)."""
    subprocess.run([netconvert, "-s", net_path, "--opendrive-output", xodr_path,
                    "--no-warnings", "true"], check=True, capture_output=True)


class SumoBridge:
    """One SUMO run. ego_id: the vehicle whose pose the session's ego car takes; the others are
    traffic. Use as a context manager, or call close()."""

    def __init__(self, net_path, step_s=0.05, ego_id="ego", sumo_binary="sumo", extra_args=(),
                 seed=1):
        self.traci = _import_traci()
        self.step_s = step_s
        self.ego_id = ego_id
        with open(net_path, encoding="utf-8") as file:
            self.net_offset = convert.net_offset(file.read(200000))
        self._ids = convert.TrafficIds()
        self._label = f"downpour-{os.getpid()}-{id(self)}"
        self.traci.start([sumo_binary, "-n", net_path, "--step-length", str(step_s),
                          "--seed", str(seed), "--no-step-log", "true", "--no-warnings", "true",
                          "--collision.action", "none", *extra_args], label=self._label)
        self.sumo = self.traci.getConnection(self._label)
        self.time_s = 0.0

    def __enter__(self):
        return self

    def __exit__(self, *exc_info):
        self.close()

    def close(self):
        if self.sumo is not None:
            self.sumo.close()
            self.sumo = None

    def add_vehicle(self, vehicle_id, edges, lane=0, depart_pos=0.0, speed=0.0, vtype=None):
        """A vehicle on a route of edges (SUMO's lane index: 0 the rightmost; or "free", "best"),
        driven by SUMO's own models."""
        route = f"route_{vehicle_id}"
        self.sumo.route.add(route, list(edges))
        kwargs = {"departLane": str(lane), "departPos": str(depart_pos),
                  "departSpeed": str(speed)}
        if vtype:
            kwargs["typeID"] = vtype
        self.sumo.vehicle.add(vehicle_id, route, **kwargs)

    def step(self):
        """One SUMO step; then the time after it."""
        self.sumo.simulationStep()
        self.time_s = self.sumo.simulation.getTime()
        return self.time_s

    def _state(self, vehicle_id, front_to_rear_axle_m):
        v = self.sumo.vehicle
        position, rotation, velocity = convert.pose(
            v.getPosition3D(vehicle_id), v.getAngle(vehicle_id), v.getSlope(vehicle_id),
            v.getSpeed(vehicle_id), front_to_rear_axle_m, self.net_offset)
        state = pb.VehicleState()
        state.position_m.x, state.position_m.y, state.position_m.z = position
        state.rotation.yaw_deg, state.rotation.pitch_deg, state.rotation.roll_deg = rotation
        state.velocity_mps.x, state.velocity_mps.y, state.velocity_mps.z = velocity
        lamps = convert.lights(v.getSignals(vehicle_id))
        state.lights.headlights = lamps["headlights"]
        state.lights.brake = lamps["brake"]
        state.lights.left_indicator = lamps["left_indicator"]
        state.lights.right_indicator = lamps["right_indicator"]
        state.lights.reverse = lamps["reverse"]
        return state

    def ego_vehicle(self):
        """The session's EgoVehicle: the SUMO ego's size (call once it is in the network)."""
        v = self.sumo.vehicle
        ego = pb.EgoVehicle()
        ego.size_m.x = min(max(v.getLength(self.ego_id), 2.0), 20.0)
        ego.size_m.y = min(max(v.getWidth(self.ego_id), 1.0), 3.5)
        ego.size_m.z = min(max(v.getHeight(self.ego_id), 1.0), 5.0)
        return ego

    def update(self, weather=None, wipers=None, max_traffic=convert.MAX_TRAFFIC):
        """The contract's Update for SUMO's state now: the ego car (if it is in the network) and
        the other vehicles nearest it (the server takes 64) as traffic; weather and wipers as
        given (pb messages, or None)."""
        u = pb.Update(sim_time_s=self.time_s, replace_traffic=True)
        present = set(self.sumo.vehicle.getIDList())
        others = sorted(present - {self.ego_id})
        if self.ego_id in present:
            v = self.sumo.vehicle
            length = min(max(v.getLength(self.ego_id), 2.0), 20.0)
            u.vehicle.CopyFrom(self._state(
                self.ego_id, convert.EGO_FRONT_BUMPER_M * length / convert.EGO_LENGTH_M))
            ex, ey = v.getPosition(self.ego_id)

            def distance(i):
                x, y = v.getPosition(i)
                return (x - ex) ** 2 + (y - ey) ** 2

            others = sorted(others, key=lambda i: (distance(i), i))
        for vehicle_id in sorted(others[:max_traffic]):
            v = self.sumo.vehicle
            klass = convert.vehicle_class(v.getVehicleClass(vehicle_id))
            length = v.getLength(vehicle_id)
            t = u.traffic.add(id=self._ids(vehicle_id), vehicle_class=klass)
            t.state.CopyFrom(self._state(
                vehicle_id, convert.traffic_front_to_rear_axle_m(klass, length)))
            t.size_m.x, t.size_m.y = length, v.getWidth(vehicle_id)
            t.size_m.z = v.getHeight(vehicle_id)
        if weather is not None:
            u.weather.CopyFrom(weather)
        if wipers is not None:
            u.wipers.CopyFrom(wipers)
        return u


def scenario_conditions(scenario, t):
    """A scenario's (weather, wipers) at t: its vehicle channel is SUMO's to drive."""
    u = scenario.at(t)
    return (u.weather if u.HasField("weather") else None,
            u.wipers if u.HasField("wipers") else None)


def run_lockstep(client, session_id, bridge, seconds, conditions=lambda t: (None, None),
                 on_step=None):
    """SUMO and the session in lockstep for `seconds`: each SUMO step is one Step of the same
    length. on_step(update, response) sees each; returns the number of steps."""
    steps = int(round(seconds / bridge.step_s))
    for _ in range(steps):
        bridge.step()
        update = bridge.update(*conditions(bridge.time_s))
        response = client.step(session_id, bridge.step_s, update)
        if on_step is not None:
            on_step(update, response)
    return steps


def run_realtime(client, session_id, bridge, seconds, conditions=lambda t: (None, None)):
    """SUMO paced by the wall clock, each step's state sent as an Update (the session renders at
    its own rate; watch its frames with WatchFrames). Returns the number of steps."""
    steps = int(round(seconds / bridge.step_s))
    start = time.monotonic()
    for k in range(steps):
        bridge.step()
        client.update(session_id, bridge.update(*conditions(bridge.time_s)))
        delay = start + (k + 1) * bridge.step_s - time.monotonic()
        if delay > 0:
            time.sleep(delay)
    return steps
