"""DownpourClient: a thin wrapper over the generated Downpour stub."""

import collections
import itertools
import logging
import os
import threading
import time

import grpc
from downpour.v1 import downpour_pb2 as pb
from downpour.v1 import downpour_pb2_grpc
from grpc_health.v1 import health_pb2, health_pb2_grpc

from .messages import mode_value, to_view_spec, view_value
# Re-exported: they lived here before.
from .security import add_security_arguments, security_options  # noqa: F401

# Four views at the largest size can exceed gRPC's default limit of 4 MiB per message.
_MAX_MESSAGE_BYTES = 64 * 1024 * 1024

_log = logging.getLogger("downpour_client")


class _CallDetails(collections.namedtuple(
        "_CallDetails", ("method", "timeout", "metadata", "credentials", "wait_for_ready",
                         "compression")), grpc.ClientCallDetails):
    pass


class _BearerToken(grpc.UnaryUnaryClientInterceptor, grpc.UnaryStreamClientInterceptor,
                   grpc.StreamUnaryClientInterceptor, grpc.StreamStreamClientInterceptor):
    """Sends "authorization: Bearer <token>" with every call (over TLS or plaintext loopback)."""

    def __init__(self, token):
        self._header = ("authorization", f"Bearer {token}")

    def _details(self, details):
        metadata = list(details.metadata or []) + [self._header]
        return _CallDetails(details.method, details.timeout, metadata, details.credentials,
                            details.wait_for_ready, details.compression)

    def intercept_unary_unary(self, continuation, details, request):
        return continuation(self._details(details), request)

    def intercept_unary_stream(self, continuation, details, request):
        return continuation(self._details(details), request)

    def intercept_stream_unary(self, continuation, details, requests):
        return continuation(self._details(details), requests)

    def intercept_stream_stream(self, continuation, details, requests):
        return continuation(self._details(details), requests)


def _read(path):
    with open(path, "rb") as file:
        return file.read()


def is_loopback(target):
    """Whether a gRPC target names this machine (a unix socket, localhost, 127.x, ::1)."""
    if target.startswith("unix:"):
        return True
    for scheme in ("dns:///", "ipv4:", "ipv6:"):
        if target.startswith(scheme):
            target = target[len(scheme):]
    host = target.rsplit(":", 1)[0] if target.count(":") == 1 or target.startswith("[") else target
    host = host.strip("[]").lower()
    return host in ("localhost", "::1") or host.startswith("127.")


class DownpourClient:
    """One channel to one server, and one more per replica that holds a session of ours. Use as a
    context manager to close the channels.

    token: the bearer token a server with a tokens file wants (default: $DOWNPOUR_TOKEN).
    tls_ca: PEM file of the CA that signed the server's certificate: connect with TLS (default:
    $DOWNPOUR_TLS_CA); tls_cert and tls_key: this client's certificate, for mutual TLS.
    stream_window_kib: the most frame data gRPC takes in ahead of the reader, per stream. A
    reader that pauses finds at most this much of old frames waiting before the latest, instead of
    the megabytes a window grown by gRPC's bandwidth probe holds (docs/contract.md, A reader
    that pauses). 0 keeps gRPC's own (faster over long, fast links). channel_options: more gRPC
    channel arguments, (name, value) pairs (e.g. ("grpc.lb_policy_name", "round_robin")).

    Scale-out: a server started with --advertise names itself in SessionInfo.endpoint, and every
    later call naming the session must go there. The client remembers the endpoint of each session
    it creates (or is told of with remember()) and sends close_session, update, step, drive and
    watch_frames for it over a channel of their own to that endpoint, with the same credentials.
    """

    def __init__(self, target="127.0.0.1:50051", timeout_s=30.0, token=None, tls_ca=None,
                 tls_cert=None, tls_key=None, stream_window_kib=256, channel_options=()):
        self.target = target
        self.timeout_s = timeout_s  # deadline of each unary call
        self._token = token if token is not None else os.environ.get("DOWNPOUR_TOKEN")
        tls_ca = tls_ca if tls_ca is not None else os.environ.get("DOWNPOUR_TLS_CA")
        self._options = [
            ("grpc.max_receive_message_length", _MAX_MESSAGE_BYTES),
            ("grpc.max_send_message_length", _MAX_MESSAGE_BYTES),
            # Reconnect within a second of a server (re)start instead of backing off for minutes.
            ("grpc.initial_reconnect_backoff_ms", 100),
            ("grpc.max_reconnect_backoff_ms", 1000),
        ]
        if stream_window_kib:
            self._options += [("grpc.http2.bdp_probe", 0),
                              ("grpc.http2.lookahead_bytes", int(stream_window_kib) * 1024)]
        self._options += list(channel_options)
        self._credentials = None
        if tls_ca:
            self._credentials = grpc.ssl_channel_credentials(
                root_certificates=_read(tls_ca),
                private_key=_read(tls_key) if tls_key else None,
                certificate_chain=_read(tls_cert) if tls_cert else None)
        self._lock = threading.Lock()
        self._endpoints = {}  # session id -> the endpoint that holds it, when not self.target
        self._stubs = {}      # endpoint -> (channel, stub), made on first use
        self._channel = self._open_channel(target)
        self.stub = downpour_pb2_grpc.DownpourStub(self._channel)
        self._health = health_pb2_grpc.HealthStub(self._channel)

    def _open_channel(self, target):
        if self._credentials is not None:
            channel = grpc.secure_channel(target, self._credentials, options=self._options)
        else:
            channel = grpc.insecure_channel(target, options=self._options)
        if self._token:
            channel = grpc.intercept_channel(channel, _BearerToken(self._token))
        return channel

    def close(self):
        with self._lock:
            others = [channel for channel, _ in self._stubs.values()]
            self._stubs.clear()
        for channel in others:
            channel.close()
        self._channel.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc_info):
        self.close()

    def remember(self, session, endpoint=None):
        """Routes later calls naming a session to the server that holds it. session: a
        SessionInfo (its endpoint is used) or a session id with endpoint. An empty endpoint, or
        this client's own target, routes it here."""
        if not isinstance(session, str):
            session, endpoint = session.session_id, getattr(session, "endpoint", "")
        if endpoint and endpoint != self.target and not self._may_follow(endpoint):
            _log.warning("not following session %s to %s: this client's token would go there "
                         "in plaintext (connect with TLS)", session, endpoint)
            endpoint = ""
        with self._lock:
            if endpoint and endpoint != self.target:
                self._endpoints[session] = endpoint
            else:
                self._endpoints.pop(session, None)

    def _may_follow(self, endpoint):
        """Whether calls may go to a server-named endpoint: the token is only sent over TLS (the
        endpoint's certificate is checked against this client's CA) or to this machine."""
        if self._credentials is not None or not self._token:
            return True
        return is_loopback(endpoint)

    def forget(self, session_id):
        with self._lock:
            self._endpoints.pop(session_id, None)

    def endpoint_of(self, session_id):
        """The target that calls naming session_id go to."""
        with self._lock:
            return self._endpoints.get(session_id, self.target)

    def stub_for(self, session_id):
        """The Downpour stub that reaches the server holding session_id."""
        with self._lock:
            endpoint = self._endpoints.get(session_id)
        return self.stub if endpoint is None else self._stub_at(endpoint)

    def _stub_at(self, endpoint):
        """The stub of another server, over a channel made on first use."""
        with self._lock:
            entry = self._stubs.get(endpoint)
            if entry is None:
                channel = self._open_channel(endpoint)
                entry = self._stubs[endpoint] = (channel, downpour_pb2_grpc.DownpourStub(channel))
            return entry[1]

    def create_session(self, views, mode="LOCKSTEP", fps=0.0, seed=0, initial=None, roads=None,
                       ego=None):
        """Views as ViewSpecs, (view, width, height[, quality]) tuples or dicts -> SessionInfo.
        roads: a RoadNetwork, {"map_name": ...} or {"opendrive_xml": ...}; None, the built-in
        track. ego: an EgoVehicle (the ego car's geometry); None, the default car's."""
        request = pb.CreateSessionRequest(
            views=[to_view_spec(v) for v in views], mode=mode_value(mode), fps=fps, seed=seed)
        if initial is not None:
            request.initial.CopyFrom(initial)
        if isinstance(roads, dict):
            roads = pb.RoadNetwork(**roads)
        if roads is not None:
            request.roads.CopyFrom(roads)
        if ego is not None:
            request.ego.CopyFrom(ego)
        return self.create_session_from(request)

    def create_session_from(self, request):
        """CreateSession -> SessionInfo; later calls naming the session go to its endpoint."""
        info = self.stub.CreateSession(request, timeout=self.timeout_s)
        self.remember(info)
        return info

    def close_session(self, session_id):
        self.stub_for(session_id).CloseSession(pb.CloseSessionRequest(session_id=session_id),
                                               timeout=self.timeout_s)
        self.forget(session_id)

    def list_sessions(self):
        """The sessions of the server at this client's target (not those of other replicas)."""
        return list(self.stub.ListSessions(pb.ListSessionsRequest(),
                                           timeout=self.timeout_s).sessions)

    def list_sessions_at(self, endpoint):
        """The sessions the server at endpoint lists (this client's credentials; the same token
        rule as for following a session)."""
        if endpoint == self.target:
            return self.list_sessions()
        if not self._may_follow(endpoint):
            raise ValueError(f"{endpoint}: this client's token would go there in plaintext")
        return list(self._stub_at(endpoint).ListSessions(pb.ListSessionsRequest(),
                                                         timeout=self.timeout_s).sessions)

    def find_session(self, session_id):
        """The SessionInfo of session_id from list_sessions(), remembered for routing; None when
        the server at this client's target does not list it."""
        for info in self.list_sessions():
            if info.session_id == session_id:
                self.remember(info)
                return info
        return None

    def update(self, session_id, update):
        """Applies a partial Update; returns the session's sim time when it was accepted."""
        request = pb.UpdateRequest(session_id=session_id, update=update)
        response = self.stub_for(session_id).Update(request, timeout=self.timeout_s)
        return response.sim_time_s

    def step(self, session_id, dt_s, update=None):
        """Lockstep: applies the update, advances dt_s, returns the frames (one per view)."""
        request = pb.StepRequest(session_id=session_id, dt_s=dt_s)
        if update is not None:
            request.update.CopyFrom(update)
        return list(self.stub_for(session_id).Step(request, timeout=self.timeout_s).frames)

    def drive(self, requests, timeout_s=None, session_id=None):
        """Streams DriveRequests; returns the call: iterate for DriveResponses, cancel() to end.
        session_id: the session driven, for routing; None takes the first request's, read here
        before the call starts when some session of this client lives elsewhere."""
        requests = iter(requests)
        with self._lock:
            routed = bool(self._endpoints)
        if session_id is None and routed:
            first = next(requests, None)
            if first is not None:
                session_id = first.session_id
                requests = itertools.chain([first], requests)
        return self.stub_for(session_id or "").Drive(requests, timeout=timeout_s)

    def watch_frames(self, session_id, views=(), max_fps=0.0, timeout_s=None):
        """Returns the call, an iterator of Frames (cancel() ends it); no views = every view."""
        request = pb.WatchFramesRequest(
            session_id=session_id, views=[view_value(v) for v in views], max_fps=max_fps)
        return self.stub_for(session_id).WatchFrames(request, timeout=timeout_s)

    def get_stats(self):
        return self.stub.GetStats(pb.GetStatsRequest(), timeout=self.timeout_s)

    def wait_until_serving(self, timeout_s=30.0, service=""):
        """Polls grpc.health.v1 Check until SERVING; raises TimeoutError after timeout_s."""
        deadline = time.monotonic() + timeout_s
        last = "no answer"
        while True:
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                raise TimeoutError(
                    f"{self.target} not SERVING after {timeout_s:g} s (last: {last})")
            try:
                response = self._health.Check(
                    health_pb2.HealthCheckRequest(service=service), timeout=min(remaining, 2.0))
                if response.status == health_pb2.HealthCheckResponse.SERVING:
                    return
                last = health_pb2.HealthCheckResponse.ServingStatus.Name(response.status)
            except grpc.RpcError as error:
                last = f"{error.code().name}: {error.details()}"
            time.sleep(min(0.1, max(0.0, deadline - time.monotonic())))
