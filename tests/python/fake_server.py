"""A tiny in-process stand-in for the Downpour server, to test the client, CLI and viewer alone.

It renders flat grey JPEGs of the requested sizes, one frame number per tick, and records the
requests it gets. It validates nothing.
"""

import io
import itertools
import threading
import time
from concurrent import futures

import grpc
from PIL import Image

import downpour_client  # noqa: F401  (puts the generated stubs on sys.path)
from downpour.v1 import downpour_pb2 as pb
from downpour.v1 import downpour_pb2_grpc
from grpc_health.v1 import health_pb2, health_pb2_grpc


def jpeg(width, height, shade):
    buffer = io.BytesIO()
    Image.new("RGB", (width, height), (shade, shade, shade)).save(buffer, "JPEG")
    return buffer.getvalue()


class FakeDownpour(downpour_pb2_grpc.DownpourServicer):
    def __init__(self):
        self.lock = threading.Lock()
        self.sessions = {}        # session id -> SessionInfo
        self.drive_requests = []  # every DriveRequest received, in order
        self.updates = []         # every UpdateRequest received, in order
        self._next_id = 0

    def _tick(self, session_id, context):
        with self.lock:
            info = self.sessions.get(session_id)
            if info is None:
                context.abort(grpc.StatusCode.NOT_FOUND, f"session_id: unknown {session_id!r}")
            info.frames_rendered += 1
            number = info.frames_rendered
        return [pb.Frame(session_id=session_id, frame_number=number, view=v.view,
                         width=v.width, height=v.height, jpeg=jpeg(v.width, v.height, number % 256))
                for v in info.views]

    def _alive(self, session_id, context):
        with self.lock:
            return context.is_active() and session_id in self.sessions

    def CreateSession(self, request, context):
        with self.lock:
            self._next_id += 1
            info = pb.SessionInfo(session_id=f"fake-{self._next_id}", mode=request.mode,
                                  fps=request.fps or 30.0, seed=request.seed, views=request.views)
            self.sessions[info.session_id] = info
            return info

    def CloseSession(self, request, context):
        with self.lock:
            self.sessions.pop(request.session_id, None)
        return pb.CloseSessionResponse()

    def ListSessions(self, request, context):
        with self.lock:
            return pb.ListSessionsResponse(sessions=self.sessions.values())

    def Update(self, request, context):
        with self.lock:
            if request.session_id not in self.sessions:
                context.abort(grpc.StatusCode.NOT_FOUND,
                              f"session_id: unknown {request.session_id!r}")
            self.updates.append(request)
            return pb.UpdateResponse(sim_time_s=request.update.sim_time_s)

    def Step(self, request, context):
        return pb.StepResponse(frames=self._tick(request.session_id, context))

    def Drive(self, request_iterator, context):
        first = next(request_iterator)
        session_id = first.session_id
        requests = itertools.chain([first], request_iterator)
        if self.sessions[session_id].mode == pb.MODE_LOCKSTEP:
            for request in requests:
                self.drive_requests.append(request)
                if request.dt_s > 0:
                    yield pb.DriveResponse(frames=self._tick(session_id, context))
            return
        reader = threading.Thread(target=self._record, args=(requests,))
        reader.start()
        while reader.is_alive() and self._alive(session_id, context):
            time.sleep(1.0 / self.sessions[session_id].fps)
            yield pb.DriveResponse(frames=self._tick(session_id, context))

    def _record(self, requests):
        try:
            for request in requests:
                self.drive_requests.append(request)
        except grpc.RpcError:
            pass  # the client cancelled

    def WatchFrames(self, request, context):
        if request.session_id not in self.sessions:
            context.abort(grpc.StatusCode.NOT_FOUND, f"session_id: unknown {request.session_id!r}")
        while self._alive(request.session_id, context):
            time.sleep(1.0 / self.sessions[request.session_id].fps)
            if self._alive(request.session_id, context):
                yield from self._tick(request.session_id, context)

    def GetStats(self, request, context):
        with self.lock:
            return pb.ServerStats(renderer="fake", sessions=len(self.sessions))


class FakeHealth(health_pb2_grpc.HealthServicer):
    def Check(self, request, context):
        return health_pb2.HealthCheckResponse(status=health_pb2.HealthCheckResponse.SERVING)


def start(fake=None):
    """(grpc server, FakeDownpour, "127.0.0.1:port"); stop it with server.stop(0). fake: the
    servicer (a FakeDownpour of a subclass), a new FakeDownpour when None."""
    server = grpc.server(futures.ThreadPoolExecutor(max_workers=16))
    fake = fake if fake is not None else FakeDownpour()
    downpour_pb2_grpc.add_DownpourServicer_to_server(fake, server)
    health_pb2_grpc.add_HealthServicer_to_server(FakeHealth(), server)
    port = server.add_insecure_port("127.0.0.1:0")
    server.start()
    return server, fake, f"127.0.0.1:{port}"
