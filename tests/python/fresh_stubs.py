"""Import first: generates the gRPC modules from the repository's proto/ with protoc into a
temporary folder and names it in DOWNPOUR_PYTHON_STUBS (for this process and the commands it
starts), so that the tests see the contract as it is now, whatever build/python holds."""

import atexit
import os
import shutil
import sys
import tempfile

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
sys.path.insert(0, os.path.join(REPO, "clients", "python"))

from downpour_client import _stubs  # noqa: E402  (imports no generated module)

if "downpour.v1" in sys.modules:
    raise ImportError("fresh_stubs: import it before anything that imports downpour.v1")
FOLDER = tempfile.mkdtemp(prefix="downpour-stubs-")
atexit.register(shutil.rmtree, FOLDER, True)
_stubs.generate(os.path.join(REPO, "proto"), FOLDER)
os.environ["DOWNPOUR_PYTHON_STUBS"] = FOLDER
