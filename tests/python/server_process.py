"""The real server binary ($DOWNPOUR_SERVER) as a child process, for the tests."""

import os
import signal
import socket
import subprocess
import tempfile
import time

SERVER = os.environ.get("DOWNPOUR_SERVER")
START_TIMEOUT_S = 60.0


def free_port():
    """A port free now on 127.0.0.1 (the server binds it a moment later)."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def accepts_flag(flag):
    """Whether the server's --help lists a flag (a server older than the contract lacks some)."""
    result = subprocess.run([SERVER, "--help"], capture_output=True, text=True, timeout=30)
    return flag in result.stdout + result.stderr


def terminate(process, timeout_s=15):
    """SIGTERM (the server drains), then a kill past timeout_s; the exit status."""
    if process.poll() is None:
        process.send_signal(signal.SIGTERM)
    try:
        return process.wait(timeout=timeout_s)
    except subprocess.TimeoutExpired:
        process.kill()
        return process.wait()


class ServerProcess:
    """Starts the server on 127.0.0.1:port (a free one when None) with extra args (after
    --warm-up minimal, unless they name it); self.target is its address once start() returned;
    stop() ends it and returns (exit code, log tail)."""

    def __init__(self, args=(), port=None):
        self.folder = tempfile.TemporaryDirectory()
        self.port = port or free_port()
        self.target = f"127.0.0.1:{self.port}"
        self.port_file = os.path.join(self.folder.name, "port")
        self.log = open(os.path.join(self.folder.name, "server.log"), "w+b")
        env = dict(os.environ, EGL_PLATFORM="surfaceless", LP_NUM_THREADS="2")
        warm_up = [] if "--warm-up" in args else ["--warm-up", "minimal"]
        self.process = subprocess.Popen(
            [SERVER, "--listen", self.target, "--port-file", self.port_file,
             "--log-level", "warn", *warm_up, *args], env=env, stdout=self.log, stderr=subprocess.STDOUT)

    def wait_started(self):
        """Waits for the port file (written once serving); raises RuntimeError with the log."""
        deadline = time.monotonic() + START_TIMEOUT_S
        while time.monotonic() < deadline:
            if self.process.poll() is not None:
                raise RuntimeError(f"server exited with {self.process.returncode}:\n{self.tail()}")
            if os.path.exists(self.port_file) and os.path.getsize(self.port_file) > 0:
                return
            time.sleep(0.05)
        raise RuntimeError(f"server not serving after {START_TIMEOUT_S:g} s:\n{self.tail()}")

    def tail(self):
        self.log.flush()
        self.log.seek(0)
        return self.log.read().decode(errors="replace")[-4000:]

    def stop(self):
        code = terminate(self.process)
        log = self.tail()
        self.log.close()
        self.folder.cleanup()
        return code, log
