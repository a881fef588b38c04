#!/usr/bin/python3
"""Writes the fuzzers' seed corpus (fuzz/corpus/<target>/) from requests a real client sends and
a few scenario files. Run with Debian's python3 and the generated stubs:
  PYTHONPATH=build/python /usr/bin/python3 fuzz/make_corpus.py
"""
import hashlib
import os
import shutil
import sys

from downpour.v1 import downpour_pb2 as pb

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CORPUS = os.path.join(ROOT, "fuzz", "corpus")


def write(target, data):
    folder = os.path.join(CORPUS, target)
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, hashlib.sha1(data).hexdigest()[:16]), "wb") as f:
        f.write(data)


def rain_update(t, rain=12.0):
    u = pb.Update(sim_time_s=t)
    u.vehicle.position_m.x = 20.0 * t
    u.vehicle.position_m.y = -5.25
    u.vehicle.velocity_mps.x = 20.0
    u.vehicle.rotation.yaw_deg = 3.0
    u.weather.rain_rate_mm_h = rain
    u.weather.wind_speed_mps = 4.0
    u.weather.cloudiness = 0.8
    u.wipers.mode = pb.WIPER_LOW
    u.replace_traffic = True
    car = u.traffic.add()
    car.id = 7
    car.state.position_m.x = 20.0 * t + 30.0
    car.state.velocity_mps.x = 18.0
    return u


def requests():
    create = pb.CreateSessionRequest(mode=pb.MODE_LOCKSTEP, seed=42, fps=30.0)
    create.views.add(view=pb.VIEW_COCKPIT, width=640, height=360, jpeg_quality=85)
    road = create.views.add(view=pb.VIEW_ROAD, width=320, height=180, jpeg_quality=70, fov_deg=60.0)
    road.camera_position_m.z = 1.5
    road.camera_rotation.pitch_deg = -5.0
    create.views.add(view=pb.VIEW_WINDSHIELD, width=256, height=256, focus_distance_m=3.0,
                     aperture_mm=2.0)
    create.initial.CopyFrom(rain_update(0.0))
    yield 0, create
    yield 0, pb.CreateSessionRequest(mode=pb.MODE_REALTIME, fps=30.0,
                                     views=[pb.ViewSpec(view=pb.VIEW_RAIN, width=16, height=16)])
    yield 1, pb.UpdateRequest(session_id="s1-" + "0" * 32, update=rain_update(1.0))
    yield 2, pb.StepRequest(session_id="s2-" + "ab" * 16, update=rain_update(0.5), dt_s=1 / 30)
    yield 3, pb.DriveRequest(session_id="s3-" + "f" * 32, update=rain_update(0.1), dt_s=0.1)
    yield 3, pb.DriveRequest(update=pb.Update(weather=pb.Weather(rain_rate_mm_h=50.0)))
    yield 4, pb.ViewSpec(view=pb.VIEW_ROAD, width=1280, height=720, jpeg_quality=90)


def random_length_string(data):
    # The framing of FuzzedDataProvider::ConsumeRandomLengthString: a backslash is doubled, and
    # a backslash followed by another byte ends the string.
    return data.replace(b"\\", b"\\\\") + b"\\n"


def main():
    for target in ("request", "scenario", "simulation", "image"):
        shutil.rmtree(os.path.join(CORPUS, target), ignore_errors=True)
    for kind, message in requests():
        write("request", bytes([kind]) + message.SerializeToString())
    # (the fuzz run adds the standard scenes, clients/scenarios/, to these)
    write("scenario", b'{"name": "x", "duration_s": 2, "keyframes": [{"t": 0, "weather": '
                      b'{"rain_rate_mm_h": 10}}, {"t": 2, "vehicle": {"position_m": [40, 0, 0]}}]}')
    write("scenario", b'{"name": "x", "keyframes": [{"t": 1.0}, {"t": 0.5}]}')
    write("scenario", b'{"name": "x", "fps": 0, "keyframes": []}')
    # Simulation: a seed byte, then framed DriveRequests: rain, wipers on, a gust, a stop.
    feed = [pb.DriveRequest(update=rain_update(0.1 * i, rain=5.0 + 10 * i), dt_s=0.1)
            for i in range(6)]
    feed.append(pb.DriveRequest(update=pb.Update(wipers=pb.WiperState(mode=pb.WIPER_HIGH)), dt_s=0.2))
    feed.append(pb.DriveRequest(update=pb.Update(weather=pb.Weather(rain_rate_mm_h=100.0,
                                                                   wind_speed_mps=25.0)),
                                dt_s=0.25))
    stop = rain_update(1.0)
    stop.vehicle.velocity_mps.x = 0.0
    feed.append(pb.DriveRequest(update=stop, dt_s=0.25))
    data = bytes([3]) + b"".join(random_length_string(r.SerializeToString()) for r in feed)
    write("simulation", data)
    write("simulation", bytes([0]) + random_length_string(feed[0].SerializeToString()))
    images()
    models()
    return 0


def models():
    """glTF seeds: a box car with a wheel node, as JSON with its buffer embedded and as binary
    glTF; and a cabin's windshield quad. The first byte is the kind (0 vehicle, 1 cabin)."""
    import base64
    import json
    import struct
    shutil.rmtree(os.path.join(CORPUS, "gltf"), ignore_errors=True)

    def box(w, h, z0, z1):
        p = [(-w, 0, z0), (w, 0, z0), (w, h, z0), (-w, h, z0),
             (-w, 0, z1), (w, 0, z1), (w, h, z1), (-w, h, z1)]
        idx = [0, 2, 1, 0, 3, 2, 4, 5, 6, 4, 6, 7, 0, 1, 5, 0, 5, 4,
               3, 7, 6, 3, 6, 2, 0, 4, 7, 0, 7, 3, 1, 2, 6, 1, 6, 5]
        return b"".join(struct.pack("<3f", *v) for v in p) + struct.pack("<36H", *idx)

    body = box(0.9, 1.4, -1.0, 3.6)
    wheel = box(0.1, 0.6, -0.3, 0.3)
    blob = body + wheel

    def document(uri):
        return {
            "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0, 1]}],
            "nodes": [{"name": "body", "mesh": 0},
                      {"name": "wheel_rl", "mesh": 1, "translation": [0.8, 0, 0],
                       "children": []}],
            "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1,
                                        "material": 0}]},
                       {"primitives": [{"attributes": {"POSITION": 2}, "indices": 3,
                                        "material": 1}]}],
            "materials": [{"name": "Paint"}, {"name": "tyre"},
                          {"name": "chrome", "pbrMetallicRoughness":
                           {"baseColorFactor": [0.6, 0.6, 0.6, 1]}}],
            "accessors": [
                {"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3"},
                {"bufferView": 1, "componentType": 5123, "count": 36, "type": "SCALAR"},
                {"bufferView": 2, "componentType": 5126, "count": 8, "type": "VEC3"},
                {"bufferView": 3, "componentType": 5123, "count": 36, "type": "SCALAR"}],
            "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 96},
                            {"buffer": 0, "byteOffset": 96, "byteLength": 72},
                            {"buffer": 0, "byteOffset": 168, "byteLength": 96},
                            {"buffer": 0, "byteOffset": 264, "byteLength": 72}],
            "buffers": [{"byteLength": len(blob), **({"uri": uri} if uri else {})}]}

    text = json.dumps(document("data:application/octet-stream;base64," +
                               base64.b64encode(blob).decode())).encode()
    write("gltf", bytes([0]) + text)
    chunk = json.dumps(document(None)).encode()
    chunk += b" " * (-len(chunk) % 4)
    glb = (struct.pack("<4sII", b"glTF", 2, 12 + 8 + len(chunk) + 8 + len(blob)) +
           struct.pack("<I4s", len(chunk), b"JSON") + chunk +
           struct.pack("<I4s", len(blob), b"BIN\0") + blob)
    write("gltf", bytes([0]) + glb)
    quad = struct.pack("<12f", 0.76, 0.98, 2.06, -0.76, 0.98, 2.06, -0.68, 1.36, 1.40,
                       0.68, 1.36, 1.40) + struct.pack("<6H", 0, 1, 2, 0, 2, 3)
    cabin = {"asset": {"version": "2.0"}, "nodes": [{"mesh": 0}],
             "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1,
                                         "material": 0}]}],
             "materials": [{"name": "windshield"}],
             "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3"},
                           {"bufferView": 1, "componentType": 5123, "count": 6,
                            "type": "SCALAR"}],
             "bufferViews": [{"buffer": 0, "byteLength": 48},
                             {"buffer": 0, "byteOffset": 48, "byteLength": 12}],
             "buffers": [{"byteLength": 60, "uri": "data:application/octet-stream;base64," +
                          base64.b64encode(quad).decode()}]}
    write("gltf", bytes([1]) + json.dumps(cabin).encode())


def images():
    """The image fuzzer's seeds: pictures of its view's size (48 x 20) as a client sends them: a
    PNG and a JPEG for the picture decoder, a 16-bit PNG for the depth decoder, and picture and depth
    together (the second byte says where the picture ends: 255 * its share)."""
    import io
    from PIL import Image  # python3-pil
    def encoded(image, kind, **options):
        out = io.BytesIO()
        image.save(out, kind, **options)
        return out.getvalue()
    picture = Image.new("RGB", (48, 20))
    picture.putdata([(x * 5, y * 12, 90) for y in range(20) for x in range(48)])
    png = encoded(picture, "PNG")
    jpeg = encoded(picture, "JPEG", quality=80)
    depth = Image.new("I;16", (48, 20))
    depth.putdata([250 + 10 * x for y in range(20) for x in range(48)])
    depth_png = encoded(depth, "PNG")
    write("image", bytes([0, 0]) + png)
    write("image", bytes([0, 0]) + jpeg)
    write("image", bytes([1, 0]) + depth_png)
    for picture_bytes in (png, jpeg):
        both = picture_bytes + depth_png
        share = round(255 * len(picture_bytes) / len(both))
        # (the encoding is the second byte modulo 4: 1 is DEPTH_PNG16_CM)
        share += (1 - share % 4) % 4
        write("image", bytes([2, min(share, 253)]) + both)


if __name__ == "__main__":
    sys.exit(main())
