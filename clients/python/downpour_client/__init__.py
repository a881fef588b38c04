"""Python client for the Downpour rain rendering server.

The generated gRPC modules live outside this package: in the folder named by the environment
variable DOWNPOUR_PYTHON_STUBS, by default <repo root>/build/python.
"""

import os
import sys
from pathlib import Path


def _add_stubs_to_path():
    default = Path(__file__).resolve().parents[3] / "build" / "python"
    folder = Path(os.environ.get("DOWNPOUR_PYTHON_STUBS") or default)
    if not (folder / "downpour" / "v1" / "downpour_pb2.py").is_file():
        raise ImportError(
            f"downpour_client: generated Python stubs not found in {folder} "
            "(run ./downpour.sh build, or set DOWNPOUR_PYTHON_STUBS to the folder that holds "
            "downpour/v1/downpour_pb2.py)")
    if str(folder) not in sys.path:
        sys.path.insert(0, str(folder))


_add_stubs_to_path()

from .client import DownpourClient, add_security_arguments, security_options  # noqa: E402
from .frames import write_frames  # noqa: E402
from .messages import (  # noqa: E402
    enum_name, mode_value, view_spec, view_value, wiper_mode_value)
from .scenario import Scenario  # noqa: E402

__all__ = [
    "DownpourClient", "Scenario", "add_security_arguments", "enum_name", "mode_value",
    "security_options", "view_spec", "view_value", "wiper_mode_value", "write_frames",
]
