"""Integration, for operators: the real server's version, Prometheus metrics, JSON logs, where a
session lives (--advertise), its health service described by reflection (as grpcurl asks), and a
crash's backtrace in the log."""

import json
import os
import re
import resource
import signal
import time
import unittest
import urllib.request

import grpc

from downpour_client import view_spec
from downpour.v1 import downpour_pb2 as pb
from grpc_health.v1 import health_pb2
from google.protobuf import descriptor_pb2

from server_process import ServerProcess, free_port
from test_server import REPO, SERVER, ServerProcessCase, inputs


def setUpModule():
    if not SERVER:
        raise unittest.SkipTest("DOWNPOUR_SERVER is not set")


def project_version():
    with open(os.path.join(REPO, "CMakeLists.txt")) as file:
        return re.search(r"project\(downpour VERSION ([0-9.]+)", file.read()).group(1)


# The reflection protocol (grpc.reflection.v1alpha), written by hand: the few fields a client
# needs to ask for the file that defines a symbol.
def _varint(value):
    out = bytearray()
    while True:
        byte = value & 0x7F
        value >>= 7
        out.append(byte | (0x80 if value else 0))
        if not value:
            return bytes(out)


def _fields(data):
    """(field number, wire type, value) of a message's length-delimited and varint fields."""
    i = 0
    while i < len(data):
        key, i = _read_varint(data, i)
        number, wire = key >> 3, key & 7
        if wire == 0:
            value, i = _read_varint(data, i)
        elif wire == 2:
            length, i = _read_varint(data, i)
            value, i = data[i:i + length], i + length
        else:
            raise ValueError(f"wire type {wire}")
        yield number, wire, value


def _read_varint(data, i):
    shift = value = 0
    while True:
        byte = data[i]
        i += 1
        value |= (byte & 0x7F) << shift
        shift += 7
        if not byte & 0x80:
            return value, i


def file_containing_symbol(channel, symbol):
    """The FileDescriptorProtos reflection gives for `symbol`, or raises with its error."""
    call = channel.stream_stream(
        "/grpc.reflection.v1alpha.ServerReflection/ServerReflectionInfo",
        request_serializer=lambda b: b, response_deserializer=lambda b: b)
    name = symbol.encode()
    request = b"\x22" + _varint(len(name)) + name  # field 4: file_containing_symbol
    for response in call(iter([request]), timeout=10):
        files = []
        for number, _, value in _fields(response):
            if number == 4:  # file_descriptor_response
                files += [descriptor_pb2.FileDescriptorProto.FromString(v)
                          for n, _, v in _fields(value) if n == 1]
            elif number == 7:  # error_response
                raise LookupError(bytes(value).decode(errors="replace"))
        return files
    raise LookupError("no response")


class OperationsTest(ServerProcessCase):
    METRICS_PORT = free_port()
    # The server's address is known ahead (a later --listen wins over the case's port 0), so
    # that it can advertise it, as a replica behind a shared name would its own.
    ADDRESS = f"127.0.0.1:{free_port()}"
    SERVER_ARGS = ["--metrics-listen", f"127.0.0.1:{METRICS_PORT}", "--log-format", "json",
                   "--log-level", "info", "--listen", ADDRESS, "--advertise", ADDRESS]

    def metrics(self):
        with urllib.request.urlopen(f"http://127.0.0.1:{self.METRICS_PORT}/metrics",
                                    timeout=10) as page:
            return page.read().decode()

    def metric(self, text, name):
        match = re.search("^" + re.escape(name) + r" ([0-9.e+-]+)$", text, re.MULTILINE)
        return float(match.group(1)) if match else None

    def test_version_and_endpoint(self):
        stats = self.client.get_stats()
        self.assertEqual(stats.version, project_version())
        self.assertEqual(stats.endpoint, self.ADDRESS)
        info = self.client.create_session([view_spec("COCKPIT", 96, 54)])
        try:
            self.assertEqual(info.endpoint, self.ADDRESS)
            listed = [s for s in self.client.list_sessions() if s.session_id == info.session_id]
            self.assertEqual(listed[0].endpoint, self.ADDRESS)
        finally:
            self.client.close_session(info.session_id)

    def test_metrics_count_frames_sessions_and_errors(self):
        before = self.metrics()
        rendered_before = self.metric(before, 'downpour_frames_total{stage="rendered"}') or 0
        info = self.client.create_session([view_spec("COCKPIT", 96, 54),
                                           view_spec("ROAD", 96, 54)])
        try:
            for step in range(5):
                self.client.step(info.session_id, 0.05, inputs(step))
            with self.assertRaises(grpc.RpcError) as refused:
                self.client.step("no-such-session", 0.05)
            self.assertEqual(refused.exception.code(), grpc.StatusCode.NOT_FOUND)
            text = self.metrics()
            self.assertGreaterEqual(
                self.metric(text, 'downpour_frames_total{stage="rendered"}') - rendered_before, 10)
            self.assertGreaterEqual(
                self.metric(text, 'downpour_frames_total{stage="encoded"}'), 10)
            self.assertGreaterEqual(self.metric(text, "downpour_render_seconds_count"), 10)
            self.assertGreaterEqual(self.metric(text, "downpour_frame_latency_seconds_count"), 10)
            self.assertGreaterEqual(
                self.metric(text, 'downpour_rpc_errors_total{code="NOT_FOUND",method="Step"}'), 1)
            self.assertGreaterEqual(
                self.metric(text, 'downpour_rpc_calls_total{code="OK",method="Step"}'), 5)
            self.assertIn(f'downpour_build_info{{renderer="', text)
            self.assertIn(f'version="{project_version()}"}} 1', text)
            # Sessions are sampled four times a second.
            deadline = 20
            while self.metric(text, 'downpour_sessions{mode="lockstep"}') != 1 and deadline:
                deadline -= 1
                self.wait(0.25)
                text = self.metrics()
            self.assertEqual(self.metric(text, 'downpour_sessions{mode="lockstep"}'), 1)
            self.assertEqual(self.metric(text, "downpour_serving"), 1)
        finally:
            self.client.close_session(info.session_id)

    def wait(self, seconds):
        time.sleep(seconds)

    def test_health_is_described_by_reflection(self):
        with grpc.insecure_channel(self.target) as channel:
            files = file_containing_symbol(channel, "grpc.health.v1.Health")
            services = {f"{f.package}.{s.name}": [m.name for m in s.method]
                        for f in files for s in f.service}
            self.assertEqual(services.get("grpc.health.v1.Health"), ["Check", "Watch"])
            files = file_containing_symbol(channel, "downpour.v1.Downpour")
            self.assertIn("downpour.v1", {f.package for f in files})
            check = channel.unary_unary(
                "/grpc.health.v1.Health/Check",
                request_serializer=health_pb2.HealthCheckRequest.SerializeToString,
                response_deserializer=health_pb2.HealthCheckResponse.FromString)
            self.assertEqual(check(health_pb2.HealthCheckRequest(), timeout=10).status,
                             health_pb2.HealthCheckResponse.SERVING)

    def test_logs_are_json_lines_with_their_session(self):
        info = self.client.create_session([view_spec("COCKPIT", 96, 54)])
        self.client.close_session(info.session_id)
        self.log.flush()
        self.log.seek(0)
        # The server's own lines; a driver's or gRPC's (rare) are not its to format.
        lines = [line for line in self.log.read().decode(errors="replace").splitlines()
                 if line.startswith("{")]
        records = [json.loads(line) for line in lines]
        self.assertTrue(all({"time", "level", "msg"} <= set(r) for r in records), lines[:3])
        started = [r for r in records if r["msg"].startswith(f"session {info.session_id} started")]
        self.assertEqual(len(started), 1, lines)
        self.assertEqual(started[0]["session"], info.session_id)
        self.assertEqual(started[0]["level"], "info")


class CrashReportTest(unittest.TestCase):
    """A server that dies of a fault says so in its log: the signal, the thread and a backtrace
    whose own frames addr2line can name; then it dies of that signal, as it would have."""

    def test_a_fatal_signal_leaves_a_backtrace_in_the_log(self):
        # No core file from it (the server inherits the limit).
        core = resource.getrlimit(resource.RLIMIT_CORE)
        resource.setrlimit(resource.RLIMIT_CORE, (0, core[1]))
        try:
            server = ServerProcess()
        finally:
            resource.setrlimit(resource.RLIMIT_CORE, core)
        try:
            server.wait_started()
            os.kill(server.process.pid, signal.SIGSEGV)
            server.process.wait(timeout=15)
        finally:
            code, log = server.stop()
        self.assertEqual(code, -signal.SIGSEGV, log)
        self.assertIn(f"fatal signal 11 (SIGSEGV) sent by process {os.getpid()} on thread", log)
        self.assertIn("backtrace:", log)
        self.assertRegex(log, r"downpour-server\(\+0x[0-9a-f]+\)")


if __name__ == "__main__":
    unittest.main()
