"""The two scenario readers agree: every file in the folders given, and the edge cases beside this
file (scenarios/), sampled every 0.05 s by the server's reader (downpour-scenes --sample) and by
the Python client's, field by field.

Usage: scenario_readers_test.py DOWNPOUR_SCENES SCENARIO_DIR...
"""

import json
import math
import subprocess
import sys
from pathlib import Path

from downpour_client.scenario import Scenario  # first: it puts the generated modules on the path
from downpour.v1 import downpour_pb2 as pb  # noqa: E402

STEP_S = 0.05
TOLERANCE = 1e-9


def python_samples(scenario, count):
    samples = []
    for i in range(count):
        update = scenario.at(i * STEP_S)
        sample = {}
        if update.HasField("vehicle"):
            v = update.vehicle
            sample["vehicle"] = {
                "position_m": [v.position_m.x, v.position_m.y, v.position_m.z],
                "rotation_deg": [v.rotation.yaw_deg, v.rotation.pitch_deg, v.rotation.roll_deg],
                "velocity_mps": [v.velocity_mps.x, v.velocity_mps.y, v.velocity_mps.z]}
        if update.HasField("wipers"):
            w = update.wipers
            sample["wipers"] = {"mode": pb.WiperMode.Name(w.mode).removeprefix("WIPER_"),
                                "interval_s": w.interval_s,
                                "blade_angle_deg": list(w.blade_angle_deg)}
        if update.HasField("weather"):
            sample["weather"] = {field.name: getattr(update.weather, field.name)
                                 for field in pb.Weather.DESCRIPTOR.fields}
        samples.append(sample)
    return samples


def differences(path, a, b):
    """Where two JSON values differ, numbers within TOLERANCE (relative for large ones)."""
    if isinstance(a, dict) and isinstance(b, dict):
        if set(a) != set(b):
            return [f"{path}: fields {sorted(a)} against {sorted(b)}"]
        return [d for key in a for d in differences(f"{path}.{key}", a[key], b[key])]
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return [f"{path}: {len(a)} items against {len(b)}"]
        return [d for i, (x, y) in enumerate(zip(a, b)) for d in differences(f"{path}[{i}]", x, y)]
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        if math.isclose(a, b, rel_tol=TOLERANCE, abs_tol=TOLERANCE):
            return []
    elif a == b:
        return []
    return [f"{path}: C++ {a!r}, Python {b!r}"]


def main():
    scenes = sys.argv[1]
    folders = [Path(f) for f in sys.argv[2:]] + [Path(__file__).resolve().parent / "scenarios"]
    files = []
    for folder in folders:
        found = sorted(folder.glob("*.json"))
        if not found:
            print(f"no scenario files in {folder}")
            return 1
        files += found
    failed = False
    for path in files:
        cpp = json.loads(subprocess.run([scenes, "--sample", str(path), str(STEP_S)], check=True,
                                        capture_output=True, text=True).stdout)
        python = python_samples(Scenario.load(str(path)), len(cpp))
        found = []
        for c, p in zip(cpp, python):
            t = c.pop("t")
            found += differences(f"t={t:g}", c, p)
        print(f"{path.name}: {len(cpp)} samples, {len(found)} differences")
        for line in found[:20]:
            print("  " + line)
        failed = failed or bool(found)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
