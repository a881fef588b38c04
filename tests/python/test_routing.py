"""Scale-out routing: calls naming a session go to SessionInfo.endpoint, the replica that holds it.

Against two in-process fake replicas behind one shared, round-robin target (as a headless Service
spreads calls), then against two real servers ($DOWNPOUR_SERVER): a session created on A reached by
a client of B, and (once the server has --advertise) the endpoint the server fills in itself.
"""

import fresh_stubs  # noqa: F401  (first: the gRPC modules of the current contract)

import os
import subprocess
import sys
import unittest

import grpc

import fake_server
from downpour_client import DownpourClient, view_spec
from downpour.v1 import downpour_pb2 as pb
from server_process import SERVER, ServerProcess, accepts_flag, free_port

CLIENT_ENV = dict(os.environ, PYTHONPATH=os.path.join(fresh_stubs.REPO, "clients", "python"))
ROUND_ROBIN = [("grpc.lb_policy_name", "round_robin")]
DT = 0.05


class FakeReplica(fake_server.FakeDownpour):
    """A fake server that says where its sessions live, as a server with --advertise does."""

    endpoint = ""

    def CreateSession(self, request, context):
        info = super().CreateSession(request, context)
        with self.lock:  # ids unique across the replicas, as the real servers' are
            del self.sessions[info.session_id]
            info.session_id = f"{self.endpoint}/{info.session_id}"
            info.endpoint = self.endpoint
            self.sessions[info.session_id] = info
        return info

    def Update(self, request, context):
        with self.lock:
            info = self.sessions.get(request.session_id)
        if info is None:
            context.abort(grpc.StatusCode.NOT_FOUND, f"session_id: unknown {request.session_id!r}")
        return pb.UpdateResponse(sim_time_s=request.update.sim_time_s)


def drive_steps(client, session_id, count):
    """count lockstep steps over one Drive stream; their responses' frame numbers."""
    requests = [pb.DriveRequest(session_id=session_id if i == 0 else "", dt_s=DT)
                for i in range(count)]
    return [r.frames[0].frame_number for r in client.drive(requests, timeout_s=30)]


class FakeReplicasTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.replicas = []
        for _ in range(2):
            server, fake, target = fake_server.start(FakeReplica())
            fake.endpoint = target
            cls.replicas.append((server, fake, target))
        cls.shared = "ipv4:" + ",".join(target for _, _, target in cls.replicas)

    @classmethod
    def tearDownClass(cls):
        for server, _, _ in cls.replicas:
            server.stop(0)

    def holder(self, session_id):
        return [t for _, fake, t in self.replicas if session_id in fake.sessions]

    def test_calls_follow_the_session_to_its_replica(self):
        with DownpourClient(self.shared, channel_options=ROUND_ROBIN) as client:
            client.wait_until_serving(10)
            sessions = [client.create_session([view_spec("COCKPIT", 32, 24)]) for _ in range(4)]
            endpoints = {info.endpoint for info in sessions}
            self.assertLessEqual(endpoints, {t for _, _, t in self.replicas})
            for info in sessions:
                self.assertEqual(self.holder(info.session_id), [info.endpoint])
                self.assertEqual(client.endpoint_of(info.session_id), info.endpoint)
                for _ in range(3):  # round robin would send every other call elsewhere
                    frames = client.step(info.session_id, DT)
                    self.assertEqual(frames[0].session_id, info.session_id)
                client.update(info.session_id, pb.Update(sim_time_s=1.0))
                self.assertEqual(drive_steps(client, info.session_id, 2), [4, 5])
                call = client.watch_frames(info.session_id)
                self.assertEqual(next(call).session_id, info.session_id)
                call.cancel()
                client.close_session(info.session_id)
                self.assertEqual(self.holder(info.session_id), [])
                self.assertEqual(client.endpoint_of(info.session_id), self.shared)
            if len(endpoints) == 2:  # the shared target does spread calls: unrouted, some fail
                lost = 0
                info = client.create_session([view_spec("RAIN", 16, 16)])
                for _ in range(6):
                    try:
                        client.stub.Step(pb.StepRequest(session_id=info.session_id, dt_s=DT),
                                         timeout=10)
                    except grpc.RpcError as error:
                        self.assertEqual(error.code(), grpc.StatusCode.NOT_FOUND)
                        lost += 1
                self.assertGreater(lost, 0)
                client.close_session(info.session_id)

    def test_a_session_created_elsewhere_is_reached_once_remembered(self):
        (_, fake_a, a), (_, fake_b, b) = self.replicas
        with DownpourClient(a) as client_a, DownpourClient(b) as client_b:
            info = client_a.create_session([view_spec("ROAD", 32, 24)])
            with self.assertRaises(grpc.RpcError) as caught:
                client_b.step(info.session_id, DT)  # B does not hold it
            self.assertEqual(caught.exception.code(), grpc.StatusCode.NOT_FOUND)
            client_b.remember(info)
            self.assertEqual(len(client_b.step(info.session_id, DT)), 1)
            client_b.close_session(info.session_id)
            self.assertNotIn(info.session_id, fake_a.sessions)

    def test_a_token_goes_to_a_named_endpoint_only_over_tls_or_on_this_machine(self):
        _, _, a = self.replicas[0]
        with DownpourClient(a, token="t" * 32) as client:
            client.remember("far", "10.1.2.3:50051")
            client.remember("near", "127.0.0.1:50999")
            self.assertEqual(client.endpoint_of("far"), a)  # not followed: plaintext token
            self.assertEqual(client.endpoint_of("near"), "127.0.0.1:50999")
        with DownpourClient(a) as client:  # no token to leak
            client.remember("far", "10.1.2.3:50051")
            self.assertEqual(client.endpoint_of("far"), "10.1.2.3:50051")
        from downpour_client.client import is_loopback
        for target, local in (("localhost:1", True), ("127.0.0.9:1", True), ("[::1]:5", True),
                              ("unix:/tmp/s", True), ("ipv4:127.0.0.1:5", True),
                              ("dns:///a.example:5", False), ("10.0.0.1:5", False),
                              ("localhost.evil.example:5", False)):
            self.assertEqual(is_loopback(target), local, target)

    def test_list_shows_the_endpoint(self):
        _, fake_a, a = self.replicas[0]
        info = fake_a.CreateSession(pb.CreateSessionRequest(views=[view_spec("RAIN", 16, 16)]),
                                    None)
        try:
            listed = subprocess.run(
                [sys.executable, "-m", "downpour_client", "list", "--server", a],
                env=CLIENT_ENV, capture_output=True, text=True, timeout=30)
            self.assertEqual(listed.returncode, 0, listed.stderr)
            self.assertRegex(listed.stdout, rf"(?m)^{info.session_id} .* endpoint={a}$")
        finally:
            fake_a.sessions.pop(info.session_id)


@unittest.skipUnless(SERVER, "DOWNPOUR_SERVER is not set")
class RealServersTest(unittest.TestCase):
    """Two real servers, A and B; each advertises its own address when it has --advertise."""

    @classmethod
    def setUpClass(cls):
        cls.advertise = accepts_flag("--advertise")
        cls.servers = []
        try:
            for _ in range(2):
                port = free_port()  # known before the start, to advertise it
                args = ["--advertise", f"127.0.0.1:{port}"] if cls.advertise else []
                cls.servers.append(ServerProcess(args, port=port))
            for server in cls.servers:
                server.wait_started()
        except BaseException:
            for server in cls.servers:
                server.stop()
            raise
        cls.a, cls.b = (s.target for s in cls.servers)

    @classmethod
    def tearDownClass(cls):
        failures = []
        for server in cls.servers:
            code, log = server.stop()
            if code != 0:
                failures.append(f"server exited with {code}:\n{log}")
        if failures:
            raise AssertionError("\n".join(failures))

    def test_a_client_of_b_drives_a_session_of_a(self):
        with DownpourClient(self.a) as client_a, DownpourClient(self.b) as client_b:
            client_a.wait_until_serving(30)
            client_b.wait_until_serving(30)
            info = client_a.create_session([view_spec("COCKPIT", 160, 90)])
            with self.assertRaises(grpc.RpcError) as caught:
                client_b.step(info.session_id, DT)
            self.assertEqual(caught.exception.code(), grpc.StatusCode.NOT_FOUND)
            # Told where it lives: by the server's endpoint, else (no --advertise) by hand.
            client_b.remember(info.session_id, info.endpoint or self.a)
            frames = client_b.step(info.session_id, DT)
            self.assertEqual((frames[0].session_id, frames[0].frame_number),
                             (info.session_id, 1))
            self.assertEqual(drive_steps(client_b, info.session_id, 3), [2, 3, 4])
            client_b.update(info.session_id, pb.Update(sim_time_s=1.0))
            self.assertNotIn(info.session_id, [s.session_id for s in client_b.list_sessions()])
            client_b.close_session(info.session_id)
            self.assertNotIn(info.session_id, [s.session_id for s in client_a.list_sessions()])

    def test_each_server_advertises_where_its_sessions_live(self):
        if not self.advertise:
            self.skipTest("the server binary has no --advertise flag yet (SessionInfo.endpoint "
                          "stays empty): rebuild it with the scale-out change and run again")
        with DownpourClient(self.a) as client_a, DownpourClient(self.b) as client_b:
            self.assertEqual(client_a.get_stats().endpoint, self.a)
            info = client_a.create_session([view_spec("RAIN", 64, 36)])
            self.assertEqual(info.endpoint, self.a)
            client_b.remember(info)
            self.assertEqual(client_b.endpoint_of(info.session_id), self.a)
            self.assertEqual(len(client_b.step(info.session_id, DT)), 1)
            listed = subprocess.run(
                [sys.executable, "-m", "downpour_client", "list", "--server", self.a],
                env=CLIENT_ENV, capture_output=True, text=True, timeout=30)
            self.assertRegex(listed.stdout, rf"(?m)^{info.session_id} .* endpoint={self.a}$")
            client_b.close_session(info.session_id)
            self.assertEqual(client_a.list_sessions(), [])
        # Both behind one round-robin name: every call still reaches the session's server.
        shared = f"ipv4:{self.a},{self.b}"
        with DownpourClient(shared, channel_options=ROUND_ROBIN) as client:
            client.wait_until_serving(30)
            sessions = [client.create_session([view_spec("RAIN", 64, 36)]) for _ in range(2)]
            for info in sessions:
                self.assertIn(info.endpoint, (self.a, self.b))
                for _ in range(3):
                    self.assertEqual(len(client.step(info.session_id, DT)), 1)
                self.assertEqual(len(drive_steps(client, info.session_id, 2)), 2)
                client.close_session(info.session_id)


    def test_the_command_line_watches_and_closes_a_session_elsewhere_by_its_endpoint(self):
        with DownpourClient(self.a) as client_a:
            info = client_a.create_session([view_spec("RAIN", 64, 36)], mode="REALTIME", fps=10)

            def cli(*args):
                return subprocess.run([sys.executable, "-m", "downpour_client", *args,
                                       "--server", self.b, "--endpoint", self.a],
                                      env=CLIENT_ENV, capture_output=True, text=True, timeout=60)

            watched = cli("watch", info.session_id, "--frames", "2")
            self.assertEqual(watched.returncode, 0, watched.stderr)
            self.assertEqual(len([line for line in watched.stdout.splitlines()
                                  if line.startswith("frame")]), 2, watched.stdout)
            closed = cli("close", info.session_id)
            self.assertEqual(closed.returncode, 0, closed.stderr)
            self.assertEqual(client_a.list_sessions(), [])


if __name__ == "__main__":
    unittest.main()
