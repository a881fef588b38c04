"""The C++ client library as a simulator vendor gets it: cmake --install of the build, the example
configured with find_package(downpour) against the installed package alone, built, and run
against the real server."""

import glob
import io
import os
import subprocess
import sys
import tempfile
import unittest

from PIL import Image

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(REPO, "tests", "python"))

from test_server import ServerProcessCase  # noqa: E402

BUILD = os.environ.get("DOWNPOUR_BUILD_DIR", os.path.join(REPO, "build"))


def run(*command):
    result = subprocess.run(command, capture_output=True, text=True, timeout=600)
    if result.returncode != 0:
        raise AssertionError(f"{' '.join(command)} failed:\n{result.stdout}\n{result.stderr}")
    return result.stdout


class CppClientPackageTest(ServerProcessCase):
    def test_the_example_builds_against_the_installed_package_and_drives_a_session(self):
        with tempfile.TemporaryDirectory() as folder:
            prefix = os.path.join(folder, "prefix")
            run("cmake", "--install", BUILD, "--prefix", prefix)
            self.assertTrue(os.path.isfile(
                os.path.join(prefix, "lib", "cmake", "downpour", "downpourConfig.cmake")))
            self.assertTrue(os.path.isfile(os.path.join(prefix, "include", "downpour",
                                                        "client.hpp")))
            self.assertTrue(os.path.isfile(os.path.join(prefix, "bin", "downpour-server")))
            example = os.path.join(folder, "example")
            run("cmake", "-S", os.path.join(REPO, "clients", "cpp", "example"), "-B", example,
                "-G", "Ninja", f"-DCMAKE_PREFIX_PATH={prefix}")
            run("cmake", "--build", example)
            out = os.path.join(folder, "frames")
            os.makedirs(out)
            printed = run(os.path.join(example, "downpour-client-example"), self.target, out)
            self.assertIn("on built-in track", printed)
            frames = sorted(glob.glob(os.path.join(out, "*.jpg")))
            self.assertEqual(len(frames), 20, printed)
            for path in frames:
                with open(path, "rb") as file, Image.open(io.BytesIO(file.read())) as image:
                    self.assertEqual((image.format, image.size), ("JPEG", (320, 180)))


    def test_the_server_installs_alone_with_its_systemd_unit(self):
        with tempfile.TemporaryDirectory() as folder:
            prefix = os.path.join(folder, "prefix")
            for component in ("server", "systemd"):
                run("cmake", "--install", BUILD, "--prefix", prefix, "--component", component)
            server = os.path.join(prefix, "bin", "downpour-server")
            self.assertRegex(run(server, "--version"), r"^downpour-server [0-9]+\.[0-9]+\.[0-9]+\n$")
            with open(os.path.join(prefix, "lib", "systemd", "system", "downpour.service")) as unit:
                text = unit.read()
            self.assertIn(f"ExecStart={server} \\\n", text)
            self.assertNotIn("@CMAKE", text)  # every placeholder filled
            # The client's files are another component's.
            self.assertFalse(os.path.exists(os.path.join(prefix, "include")))


if __name__ == "__main__":
    unittest.main()
