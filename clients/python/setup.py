"""Builds downpour-client with the gRPC modules generated from the repository's .proto files.

build_py runs protoc (with grpc_python_plugin, or grpcio-tools' own) over proto/downpour/v1 and
proto/grpc_health/v1 into downpour_client/_generated/, which the package puts on sys.path. The
.proto files are found in $DOWNPOUR_PROTO_DIR, else ../../proto (this folder in the repository),
else ./proto (an sdist, which carries them). The version is the repository's CMake project
version.
"""

import importlib.util
import os
import shutil
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py
from setuptools.command.sdist import sdist

HERE = Path(__file__).resolve().parent
FALLBACK_VERSION = "0.1.0"


def _stubs_module():
    """downpour_client/_stubs.py, loaded alone (the package itself needs what is built here)."""
    spec = importlib.util.spec_from_file_location("_downpour_stubs",
                                                  HERE / "downpour_client" / "_stubs.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


STUBS = _stubs_module()


def _proto_root():
    candidates = [os.environ.get("DOWNPOUR_PROTO_DIR"), HERE / "proto", HERE.parents[1] / "proto"]
    for folder in candidates:
        if folder and all((Path(folder) / p).is_file() for p in STUBS.PROTOS):
            return Path(folder)
    raise SystemExit("downpour-client: the .proto files were not found (set DOWNPOUR_PROTO_DIR "
                     "to the repository's proto/ folder)")


def _version():
    if (HERE / "PKG-INFO").is_file():  # an sdist
        for line in (HERE / "PKG-INFO").read_text(encoding="utf-8").splitlines():
            if line.startswith("Version:"):
                return line.split(":", 1)[1].strip()
    return STUBS.cmake_version(HERE.parents[1] / "CMakeLists.txt") or FALLBACK_VERSION


VERSION = _version()


class BuildWithStubs(build_py):
    """build_py, then the generated modules and _version.py into the built package."""

    def run(self):
        super().run()
        package = Path(self.build_lib) / "downpour_client"
        generated = package / "_generated"
        if not self.dry_run:
            shutil.rmtree(generated, ignore_errors=True)
            try:
                STUBS.generate(_proto_root(), generated)
            except RuntimeError as error:
                raise SystemExit(f"downpour-client: generating the gRPC modules: {error}")
            (package / "_version.py").write_text(f'version = "{VERSION}"\n', encoding="utf-8")

    def get_outputs(self, include_bytecode=True):
        package = Path(self.build_lib) / "downpour_client"
        extra = [str(p) for p in (package / "_generated").rglob("*.py")]
        return super().get_outputs(include_bytecode) + extra + [str(package / "_version.py")]


class SdistWithProtos(sdist):
    """An sdist that carries the .proto files (./proto), to build from alone."""

    def make_release_tree(self, base_dir, files):
        super().make_release_tree(base_dir, files)
        root = _proto_root()
        for name in STUBS.PROTOS:
            target = Path(base_dir) / "proto" / name
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(root / name, target)


setup(version=VERSION, packages=["downpour_client"],
      cmdclass={"build_py": BuildWithStubs, "sdist": SdistWithProtos})
