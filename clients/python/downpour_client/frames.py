"""Frames to files."""

import os

from downpour.v1 import downpour_pb2 as pb


def write_frames(out_dir, frames):
    """Writes each frame as OUT_DIR/<frame number>_<VIEW>.jpg (the folder made if need be)."""
    os.makedirs(out_dir, exist_ok=True)
    for f in frames:
        name = f"{f.frame_number:05d}_{pb.View.Name(f.view)}.jpg"
        with open(os.path.join(out_dir, name), "wb") as file:
            file.write(f.jpeg)
