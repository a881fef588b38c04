"""Frames to files, and to plain records."""

import os

from downpour.v1 import downpour_pb2 as pb

from .messages import enum_name, message_dict


def write_frames(out_dir, frames):
    """Writes each frame as OUT_DIR/<frame number>_<VIEW>.jpg (the folder made if need be)."""
    os.makedirs(out_dir, exist_ok=True)
    for f in frames:
        name = f"{f.frame_number:05d}_{pb.View.Name(f.view)}.jpg"
        with open(os.path.join(out_dir, name), "wb") as file:
            file.write(f.jpeg)


def frame_record(frame):
    """A Frame as a JSON-ready dict, every field but the JPEG itself (its size instead):
    frame_number, sim_time_s, view ("COCKPIT"), width, height, stats (render/encode ms, wet
    fractions, road states...), tires, ego_place, as proto3's JSON mapping names them, with the
    64-bit counters as numbers."""
    meta = pb.Frame()
    meta.CopyFrom(frame)
    meta.ClearField("jpeg")
    record = message_dict(meta)
    record["frame_number"] = frame.frame_number
    record["view"] = enum_name(pb.View, frame.view)
    record["jpeg_bytes"] = len(frame.jpeg)
    if "stats" in record:
        record["stats"]["frames_dropped"] = frame.stats.frames_dropped
    return record
