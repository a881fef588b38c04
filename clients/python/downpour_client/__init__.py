"""Python client for the Downpour rain rendering server.

The generated gRPC modules (downpour.v1, grpc_health.v1) are found when first imported, not when
this package is: an installed package carries them (downpour_client/_generated); a source checkout
takes $DOWNPOUR_PYTHON_STUBS or <repo root>/build/python, else generates them with protoc into a
cache folder (see _stubs.py). So `import downpour_client; from downpour.v1 import downpour_pb2`
works, and so does the command line's --help with no generated modules at all.
"""

import importlib
import sys

from . import _stubs

_stubs_folder = None


def ensure_stubs():
    """Puts the folder of the generated modules on sys.path (once) and returns it; raises
    ImportError saying what to do when there is none."""
    global _stubs_folder
    if _stubs_folder is None:
        folder = str(_stubs.find_stubs())
        if folder not in sys.path:
            sys.path.insert(0, folder)
        _stubs_folder = folder
    return _stubs_folder


class _StubsFinder:
    """Finds nothing itself: on the first import of a generated top-level package it puts the
    stubs' folder on sys.path, where the ordinary finders that come after it look."""

    @staticmethod
    def find_spec(name, path=None, target=None):
        if _stubs_folder is None and path is None:
            if name == "downpour":
                ensure_stubs()
            elif name == "grpc_health":  # pip's grpcio-health-checking may provide it instead
                try:
                    ensure_stubs()
                except ImportError:
                    pass
        return None


if not any(isinstance(f, _StubsFinder) for f in sys.meta_path):
    sys.meta_path.insert(0, _StubsFinder())


def _version():
    try:
        from ._version import version  # written by setup.py in an installed package
        return version
    except ImportError:
        return _stubs.cmake_version(_stubs.REPO_ROOT / "CMakeLists.txt") or "0.0.0+unknown"


__version__ = _version()

# The public names, imported on first use (they need the generated modules).
_EXPORTS = {
    "DownpourClient": "client", "add_security_arguments": "security",
    "security_options": "security", "write_frames": "frames", "enum_name": "messages",
    "mode_value": "messages", "view_spec": "messages", "view_value": "messages",
    "wiper_mode_value": "messages", "Scenario": "scenario",
}

__all__ = sorted(_EXPORTS) + ["ensure_stubs"]


def __getattr__(name):
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{module}", __name__), name)
    globals()[name] = value
    return value
