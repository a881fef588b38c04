"""Where the generated gRPC modules (downpour.v1, grpc_health.v1) come from, and how to make them.

The generated code imports itself absolutely (`from downpour.v1 import downpour_pb2`), so the
folder that holds it goes on sys.path. Looked for, in order:

  1. $DOWNPOUR_PYTHON_STUBS, when set (it must hold them);
  2. downpour_client/_generated/, which an installed package carries (setup.py makes it);
  3. <repo root>/build/python, which the C++ build makes (a source checkout);
  4. a cache folder ($DOWNPOUR_STUBS_CACHE, else ~/.cache/downpour-client) that protoc fills from
     the .proto files ($DOWNPOUR_PROTO_DIR, else <repo root>/proto), once per version of them.

This module imports nothing of the package: setup.py loads it by path to generate the modules at
build time.
"""

import hashlib
import importlib.util
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

PACKAGE_DIR = Path(__file__).resolve().parent
GENERATED_DIR = PACKAGE_DIR / "_generated"
REPO_ROOT = PACKAGE_DIR.parents[2]  # clients/python/downpour_client -> the repository
PROTOS = ("downpour/v1/downpour.proto", "grpc_health/v1/health.proto")
MODULES = ("downpour/v1/downpour_pb2.py", "downpour/v1/downpour_pb2_grpc.py",
           "grpc_health/v1/health_pb2.py", "grpc_health/v1/health_pb2_grpc.py")


def holds_stubs(folder):
    """Whether folder holds every generated module."""
    return folder is not None and all((Path(folder) / m).is_file() for m in MODULES)


def proto_root():
    """The folder of the .proto files ($DOWNPOUR_PROTO_DIR or the repo's proto/), or None."""
    folder = Path(os.environ.get("DOWNPOUR_PROTO_DIR") or REPO_ROOT / "proto")
    return folder if all((folder / p).is_file() for p in PROTOS) else None


def _protoc_command():
    """protoc with the gRPC Python plugin as a command prefix, or None when neither is here:
    Debian's protoc and grpc_python_plugin, else grpcio-tools' bundled protoc."""
    protoc = shutil.which("protoc")
    plugin = shutil.which("grpc_python_plugin")
    if protoc and plugin:
        return [protoc, f"--plugin=protoc-gen-grpc_python={plugin}"]
    if importlib.util.find_spec("grpc_tools") is not None:
        return [sys.executable, "-m", "grpc_tools.protoc"]
    return None


def generate(protos, out_dir):
    """Runs protoc over PROTOS in protos (a folder) into out_dir (made if need be)."""
    command = _protoc_command()
    if command is None:
        raise RuntimeError("neither protoc with grpc_python_plugin (Debian: protobuf-compiler, "
                           "protobuf-compiler-grpc) nor grpcio-tools is installed")
    os.makedirs(out_dir, exist_ok=True)
    result = subprocess.run(
        command + [f"-I{protos}", f"--python_out={out_dir}", f"--grpc_python_out={out_dir}"]
        + [str(Path(protos) / p) for p in PROTOS], capture_output=True, text=True)
    if result.returncode != 0:
        raise RuntimeError(f"protoc failed ({result.returncode}): {result.stderr.strip()}")
    if not holds_stubs(out_dir):
        raise RuntimeError(f"protoc left no generated modules in {out_dir}")


def _cache_dir():
    base = os.environ.get("DOWNPOUR_STUBS_CACHE")
    if base:
        return Path(base)
    xdg = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(xdg) / "downpour-client"


def generate_cached(protos):
    """The stubs of these .proto files in the cache, generated unless already there."""
    digest = hashlib.sha256()
    for name in PROTOS:
        digest.update(name.encode() + b"\0" + (Path(protos) / name).read_bytes())
    try:
        from google.protobuf import __version__ as protobuf_version
    except ImportError:
        protobuf_version = "none"
    digest.update(protobuf_version.encode())
    folder = _cache_dir() / f"stubs-{digest.hexdigest()[:16]}"
    if holds_stubs(folder):
        return folder
    folder.parent.mkdir(parents=True, exist_ok=True)
    # Made aside and renamed into place, so that a concurrent process never sees half of it.
    scratch = tempfile.mkdtemp(prefix=".stubs-", dir=folder.parent)
    try:
        generate(protos, scratch)
        try:
            os.rename(scratch, folder)
        except OSError:
            if not holds_stubs(folder):  # not another process's finished copy
                raise
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
    return folder


def find_stubs(allow_generate=True):
    """The folder of the generated modules; raises ImportError saying what to do when none."""
    named = os.environ.get("DOWNPOUR_PYTHON_STUBS")
    if named:
        if holds_stubs(named):
            return Path(named)
        raise ImportError(
            f"downpour_client: DOWNPOUR_PYTHON_STUBS={named} does not hold the generated modules "
            "(downpour/v1/downpour_pb2.py ...); run ./downpour.sh build, or unset it")
    for folder in (GENERATED_DIR, REPO_ROOT / "build" / "python"):
        if holds_stubs(folder):
            return folder
    protos = proto_root()
    if allow_generate and protos is not None:
        try:
            return generate_cached(protos)
        except (OSError, RuntimeError) as error:
            raise ImportError(f"downpour_client: cannot generate the gRPC modules from "
                              f"{protos}: {error}") from None
    raise ImportError(
        "downpour_client: generated gRPC modules not found: install the package (pip install "
        "clients/python), build the server (./downpour.sh build) or set DOWNPOUR_PYTHON_STUBS to "
        "a folder holding downpour/v1/downpour_pb2.py; or set DOWNPOUR_PROTO_DIR to the proto/ "
        "folder with protoc and grpc_python_plugin installed")


def cmake_version(cmake_lists):
    """x.y.z of `project(NAME VERSION x.y.z ...)` in a CMakeLists.txt, or None."""
    try:
        text = Path(cmake_lists).read_text(encoding="utf-8")
    except OSError:
        return None
    match = re.search(r"project\s*\([^)]*?\bVERSION\s+([0-9]+(?:\.[0-9]+)*)", text)
    return match.group(1) if match else None
