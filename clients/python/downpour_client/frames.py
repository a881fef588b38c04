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


# A frame's files (Frame fields) and the name each takes beside the frame's stem (save_frame_files).
_FILES = {"jpeg": ".jpg", "clean_jpeg": "_clean.jpg", "water_mask_png": "_mask.png",
          "depth_png": "_depth.png"}


def save_frame_files(out_dir, stem, frame):
    """Writes the frame and the ground truth it brings (ViewSpec.outputs) as OUT_DIR/STEM.jpg,
    STEM_clean.jpg, STEM_mask.png and STEM_depth.png; returns the names written, by field."""
    written = {}
    for field, suffix in _FILES.items():
        data = getattr(frame, field)
        if data:
            written[field] = stem + suffix
            with open(os.path.join(out_dir, stem + suffix), "wb") as file:
                file.write(data)
    return written


def frame_record(frame):
    """A Frame as a JSON-ready dict, every field but its files (the JPEG and any ground truth: their
    sizes instead, jpeg_bytes, clean_jpeg_bytes...):
    frame_number, sim_time_s, view ("COCKPIT"), width, height, stats (render/encode ms, wet
    fractions, road states...), tires, ego_place, as proto3's JSON mapping names them, with the
    64-bit counters as numbers."""
    meta = pb.Frame()
    meta.CopyFrom(frame)
    for field in _FILES:
        meta.ClearField(field)
    record = message_dict(meta)
    record["frame_number"] = frame.frame_number
    record["view"] = enum_name(pb.View, frame.view)
    record["jpeg_bytes"] = len(frame.jpeg)
    for field in _FILES:
        if field != "jpeg" and getattr(frame, field):
            record[field + "_bytes"] = len(getattr(frame, field))
    if "stats" in record:
        record["stats"]["frames_dropped"] = frame.stats.frames_dropped
    return record
