"""The per-call service path: records split across packets, records larger than the preallocated
buffer, ok=0 responses, a server dying mid-response, requests sent ahead, and one persistent proxy
shared by two threads.

The wire-level cases talk to a scripted raw-socket server (no master: a stub node answers
``lookupService``), so each packet boundary is chosen by the test, not by the kernel.
"""

from __future__ import annotations

import socket
import struct
import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field

import pytest
from node_msgs import AddTwoInts, String, Trigger

from ninjemys.errors import ProtocolError, ServiceError, ShutdownError
from ninjemys.node.services import ServiceProxy, _Link
from ninjemys.wire import headers
from ninjemys.wire.tcpros import SERVICE_RESPONSE_HEAD, encode_service_response

_U32 = struct.Struct("<I")


class Echo:
    """A test-local service: string in, the same string out (exercises large requests and responses)."""

    _type = "ninjemys_test/Echo"
    _md5sum = "0123456789abcdef0123456789abcdef"
    _request_class = String
    _response_class = String


# --- a scripted server ---------------------------------------------------------------------------


def _recv_exact(conn: socket.socket, n: int) -> bytes:
    data = b""
    while len(data) < n:
        chunk = conn.recv(n - len(data))
        if not chunk:
            raise ConnectionError("client closed")
        data += chunk
    return data


def _read_record(conn: socket.socket) -> bytes:
    (n,) = _U32.unpack(_recv_exact(conn, 4))
    return _recv_exact(conn, n)


def _send_in_pieces(conn: socket.socket, data: bytes, cuts: list[int]) -> None:
    """Send ``data`` as separate TCP segments cut at ``cuts`` (TCP_NODELAY plus a pause each)."""
    last = 0
    for cut in [*cuts, len(data)]:
        conn.sendall(data[last:cut])
        last = cut
        time.sleep(0.005)


@dataclass
class ScriptedServer:
    """Accepts connections, answers the header as a ROS service would, then runs ``script(conn)``
    for each request; ``connections`` counts accepted clients."""

    service_class: type
    script: Callable[[socket.socket, bytes], None]
    connections: int = 0
    _sock: socket.socket = field(default_factory=socket.socket)
    _threads: list[threading.Thread] = field(default_factory=list)
    _conns: list[socket.socket] = field(default_factory=list)

    def start(self) -> str:
        self._sock.bind(("127.0.0.1", 0))
        self._sock.listen(8)
        thread = threading.Thread(target=self._accept, daemon=True)
        thread.start()
        self._threads.append(thread)
        return f"rosrpc://127.0.0.1:{self._sock.getsockname()[1]}"

    def _accept(self) -> None:
        while True:
            try:
                conn, _ = self._sock.accept()
            except OSError:
                return
            conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            self.connections += 1
            self._conns.append(conn)
            thread = threading.Thread(target=self._serve, args=(conn,), daemon=True)
            thread.start()
            self._threads.append(thread)

    def _serve(self, conn: socket.socket) -> None:
        try:
            (n,) = _U32.unpack(_recv_exact(conn, 4))
            _recv_exact(conn, n)
            reply = {"callerid": "/scripted", "type": self.service_class._type}
            reply["md5sum"] = self.service_class._md5sum
            conn.sendall(headers.encode_header(reply))
            while True:
                self.script(conn, _read_record(conn))
        except OSError:
            pass
        finally:
            conn.close()

    def stop(self) -> None:
        try:
            self._sock.shutdown(socket.SHUT_RDWR)  # wakes the accepting thread (close alone does not)
        except OSError:
            pass
        self._sock.close()
        for conn in self._conns:
            try:
                conn.shutdown(socket.SHUT_RDWR)
            except OSError:
                pass
        for thread in self._threads:
            thread.join(2)


class _StubMaster:
    def __init__(self, uri: str) -> None:
        self.uri = uri

    def lookup_service(self, name: str) -> str:
        return self.uri


class _StubNode:
    """What a ServiceProxy uses of its node when calling: a name and the master's lookupService."""

    def __init__(self, uri: str) -> None:
        self.name = "/fastpath_test"
        self.master = _StubMaster(uri)


@pytest.fixture
def scripted() -> Iterator[Callable[..., tuple[ScriptedServer, _StubNode]]]:
    servers: list[ScriptedServer] = []

    def make(service_class: type, script: Callable[[socket.socket, bytes], None]):
        server = ScriptedServer(service_class, script)
        servers.append(server)
        return server, _StubNode(server.start())

    try:
        yield make
    finally:
        for server in servers:
            server.stop()


def _ok(payload: bytes) -> bytes:
    return encode_service_response(True, payload)


def _sum_reply(body: bytes) -> bytes:
    a, b = struct.unpack("<qq", body)
    return _ok(struct.pack("<q", a + b))


# --- the client's read of a response ------------------------------------------------------------


def test_response_split_at_every_field_boundary(scripted) -> None:
    # the ok byte, the length in two halves and the body in two parts each arrive as their own segment
    def script(conn: socket.socket, body: bytes) -> None:
        _send_in_pieces(conn, _sum_reply(body), [1, 3, 5, 9])

    _, node = scripted(AddTwoInts, script)
    proxy = ServiceProxy(node, "/add", AddTwoInts, persistent=True)
    assert [proxy(i, 100).sum for i in range(3)] == [100, 101, 102]
    proxy.close()


def test_response_split_byte_by_byte_then_whole_again(scripted) -> None:
    calls = []

    def script(conn: socket.socket, body: bytes) -> None:
        reply = _sum_reply(body)
        calls.append(len(reply))
        _send_in_pieces(conn, reply, list(range(1, len(reply))) if len(calls) == 1 else [])

    _, node = scripted(AddTwoInts, script)
    proxy = ServiceProxy(node, "/add", AddTwoInts, persistent=True)
    assert proxy(2, 3).sum == 5  # 13 one-byte segments
    assert proxy(4, 5).sum == 9  # one segment: the buffer state was left clean
    proxy.close()


@pytest.mark.parametrize("size", [40_000, 70_000, 3_000_000])
def test_response_larger_than_the_buffer_share(scripted, size: int) -> None:
    # 40 kB fits the 64 kB buffer but not always in one read; 70 kB and 3 MB get their own buffer
    text = "".join(chr(ord("a") + i % 26) for i in range(size))

    def script(conn: socket.socket, body: bytes) -> None:
        if String.deserialize_from(body).data == "big":
            _send_in_pieces(conn, _ok(String(text).serialize_to_bytes()), [3, 5000])
        else:
            conn.sendall(_ok(body))

    _, node = scripted(Echo, script)
    proxy = ServiceProxy(node, "/echo", Echo, persistent=True)
    assert proxy("small").data == "small"
    assert proxy("big").data == text
    assert proxy("small again").data == "small again"
    proxy.close()


def test_error_response_raises_with_the_servers_text_and_keeps_the_connection(scripted) -> None:
    def script(conn: socket.socket, body: bytes) -> None:
        a, _ = struct.unpack("<qq", body)
        if a < 0:
            _send_in_pieces(conn, encode_service_response(False, "negative: no"), [1, 4])
        else:
            conn.sendall(_sum_reply(body))

    server, node = scripted(AddTwoInts, script)
    proxy = ServiceProxy(node, "/add", AddTwoInts, persistent=True)
    assert proxy(1, 1).sum == 2
    with pytest.raises(ServiceError, match=r"responded with an error: negative: no$"):
        proxy(-1, 0)
    assert proxy(3, 4).sum == 7
    assert server.connections == 1
    proxy.close()


def test_server_closing_mid_response_fails_the_call_and_the_next_call_reconnects(scripted) -> None:
    replies = []

    def script(conn: socket.socket, body: bytes) -> None:
        reply = _sum_reply(body)
        replies.append(reply)
        if len(replies) == 2:
            conn.sendall(reply[:7])  # ok byte, length, 2 of 8 body bytes: then the server dies
            conn.close()
            raise ConnectionError("scripted death")
        conn.sendall(reply)

    server, node = scripted(AddTwoInts, script)
    proxy = ServiceProxy(node, "/add", AddTwoInts, persistent=True)
    assert proxy(1, 2).sum == 3
    with pytest.raises(ServiceError, match=r"transport error .*after 2 of 8 bytes"):
        proxy(5, 5)
    assert proxy._sock is None  # the broken connection is not reused
    assert proxy(7, 8).sum == 15
    assert server.connections == 2
    proxy.close()


def test_server_closing_before_the_ok_byte(scripted) -> None:
    def script(conn: socket.socket, body: bytes) -> None:
        conn.close()
        raise ConnectionError("scripted death")

    _, node = scripted(AddTwoInts, script)
    proxy = ServiceProxy(node, "/add", AddTwoInts, persistent=True)
    with pytest.raises(ServiceError, match="transport error completing the call"):
        proxy(1, 2)


def test_a_bogus_response_length_is_refused_without_allocating(scripted) -> None:
    def script(conn: socket.socket, body: bytes) -> None:
        conn.sendall(SERVICE_RESPONSE_HEAD.pack(1, 0xFFFFFFF0))

    _, node = scripted(AddTwoInts, script)
    proxy = ServiceProxy(node, "/add", AddTwoInts, persistent=True)
    with pytest.raises(ServiceError, match="exceeds the"):
        proxy(1, 2)
    assert proxy._sock is None


def test_non_persistent_proxy_uses_one_connection_per_call(scripted) -> None:
    server, node = scripted(AddTwoInts, lambda conn, body: conn.sendall(_sum_reply(body)))
    proxy = ServiceProxy(node, "/add", AddTwoInts)
    assert [proxy(i, i).sum for i in range(3)] == [0, 2, 4]
    assert server.connections == 3
    assert proxy._sock is None


def test_request_without_arguments_is_the_default_request_every_time(scripted) -> None:
    seen: list[bytes] = []

    def script(conn: socket.socket, body: bytes) -> None:
        seen.append(body)
        conn.sendall(_sum_reply(body))

    _, node = scripted(AddTwoInts, script)
    proxy = ServiceProxy(node, "/add", AddTwoInts, persistent=True)
    assert proxy().sum == 0
    assert proxy(a=2, b=2).sum == 4
    assert proxy().sum == 0
    assert seen == [bytes(16), struct.pack("<qq", 2, 2), bytes(16)]
    proxy.close()
    with pytest.raises(ShutdownError):
        proxy()


# --- the link itself, over a socket pair --------------------------------------------------------


@pytest.fixture
def pair() -> Iterator[tuple[socket.socket, socket.socket]]:
    a, b = socket.socketpair()
    try:
        yield a, b
    finally:
        a.close()
        b.close()


def test_link_keeps_bytes_past_a_record_for_the_next(pair) -> None:
    a, b = pair
    link = _Link(a, size=64)
    b.sendall(_U32.pack(3) + b"one" + _U32.pack(0) + _U32.pack(5) + b"th")
    assert link.take(_U32) == (3, b"one")
    assert link.take(_U32) == (0, b"")
    b.sendall(b"ree")
    assert link.take(_U32) == (5, b"three")


def test_link_bodies_are_fresh_copies(pair) -> None:
    # deserialization keeps views into the body, so the next read must not overwrite it
    a, b = pair
    link = _Link(a, size=64)
    b.sendall(_U32.pack(4) + b"aaaa")
    first = link.take(_U32)[1]
    b.sendall(_U32.pack(4) + b"bbbb")
    assert link.take(_U32)[1] == b"bbbb"
    assert first == b"aaaa"


def test_link_compacts_a_record_that_would_run_past_the_buffer_end(pair) -> None:
    a, b = pair
    link = _Link(a, size=64)
    b.sendall(_U32.pack(50) + b"x" * 50 + _U32.pack(20) + b"y" * 4)  # 2nd record starts at byte 54
    assert link.take(_U32)[1] == b"x" * 50
    b.sendall(b"y" * 16)
    assert link.take(_U32)[1] == b"y" * 20


def test_link_receives_a_large_record_into_its_own_buffer(pair) -> None:
    a, b = pair
    link = _Link(a, size=64)
    payload = bytes(range(256)) * 4
    b.sendall(_U32.pack(len(payload)) + payload + _U32.pack(1) + b"z")
    assert link.take(_U32)[1] == payload
    assert link.take(_U32)[1] == b"z"


def test_link_reports_where_the_peer_vanished(pair) -> None:
    a, b = pair
    link = _Link(a, size=64)
    b.sendall(SERVICE_RESPONSE_HEAD.pack(1, 10) + b"abc")
    b.shutdown(socket.SHUT_WR)
    with pytest.raises(ConnectionError, match="after 3 of 10 bytes"):
        link.take(SERVICE_RESPONSE_HEAD)


def test_link_refuses_an_oversized_length(pair) -> None:
    a, b = pair
    b.sendall(_U32.pack(1000))
    with pytest.raises(ProtocolError, match="1000"):
        _Link(a, size=64).take(_U32, limit=999)


# --- real nodes: the server's per-connection thread ---------------------------------------------


def test_two_threads_share_one_persistent_proxy(make_node) -> None:
    server, client = make_node("server"), make_node("client")
    served_by: set[int] = set()

    def handler(req):
        served_by.add(threading.get_ident())
        return req.a + req.b

    server.service("add", AddTwoInts, handler)
    client.wait_for_service("add", timeout=5)
    proxy = client.service_proxy("add", AddTwoInts, persistent=True)
    results: dict[int, list[int]] = {1: [], 2: []}
    errors: list[BaseException] = []

    def work(tag: int) -> None:
        try:
            for i in range(300):
                results[tag].append(proxy(i, tag * 1_000_000).sum)
        except BaseException as exc:  # reported by the assertion below
            errors.append(exc)

    threads = [threading.Thread(target=work, args=(tag,)) for tag in results]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(10)
    assert not errors
    for tag, sums in results.items():
        assert sums == [i + tag * 1_000_000 for i in range(300)]
    assert len(served_by) == 1  # one connection, so one server thread answered all 600 calls


def test_server_answers_requests_sent_ahead_in_order(make_node) -> None:
    from ninjemys.net.addresses import split_uri

    server = make_node("server")
    server.service("add", AddTwoInts, lambda r: r.a + r.b)
    host, port = split_uri(server.master.lookup_service("/add"))
    with socket.create_connection((host, port), timeout=5) as sock:
        fields = {"callerid": "/raw", "service": "/add", "md5sum": AddTwoInts._md5sum, "persistent": "1"}
        sock.sendall(headers.encode_header(fields))
        link = _Link(sock)
        assert link.header()["type"] == AddTwoInts._type
        requests = b"".join(_U32.pack(16) + struct.pack("<qq", i, 10) for i in range(5))
        sock.sendall(requests)  # five requests in one segment
        for i in range(5):
            ok, body = link.take(SERVICE_RESPONSE_HEAD)
            assert (ok, struct.unpack("<q", body)[0]) == (1, i + 10)


def test_server_large_request_and_response(make_node) -> None:
    server, client = make_node("server"), make_node("client")
    server.service("echo", Echo, lambda req: String(req.data[::-1]))
    client.wait_for_service("echo", timeout=5)
    proxy = client.service_proxy("echo", Echo, persistent=True)
    text = "".join(chr(ord("a") + i % 26) for i in range(1_000_000))
    assert proxy("abc").data == "cba"
    assert proxy(text).data == text[::-1]
    assert proxy("xyz").data == "zyx"


def test_server_handler_errors_and_bad_requests_keep_the_connection(make_node) -> None:
    server, client = make_node("server"), make_node("client")

    def handler(req):
        if req.a == 13:
            raise RuntimeError("unlucky")
        if req.a == 14:
            return None
        if req.a == 15:
            raise ServiceError("not today")  # a refusal on purpose: rospy's ServiceException
        if req.a == 16:
            return (1, 2, 3)
        return req.a + req.b

    server.service("add", AddTwoInts, handler)
    client.wait_for_service("add", timeout=5)
    proxy = client.service_proxy("add", AddTwoInts, persistent=True)
    with pytest.raises(ServiceError, match="error processing request: unlucky"):
        proxy(13, 0)
    with pytest.raises(ServiceError, match=r"service cannot process request: service handler returned None$"):
        proxy(14, 0)
    with pytest.raises(
        ServiceError, match=r"responded with an error: service cannot process request: not today$"
    ):
        proxy(15, 0)
    with pytest.raises(
        ServiceError, match=r"service cannot process request: handler returned wrong number of values"
    ):
        proxy(16, 0)
    # a request of the wrong size does not deserialize: ok=0, and the connection still serves
    proxy._link.sendall(_U32.pack(3) + b"abc")
    ok, body = proxy._link.take(SERVICE_RESPONSE_HEAD)
    assert ok == 0 and body.startswith(b"cannot deserialize request")
    assert proxy(20, 22).sum == 42


def test_persistent_proxy_reconnects_after_the_server_restarts(make_node) -> None:
    client = make_node("client")
    first = make_node("server_a")
    first.service("/svc", Trigger, lambda req: (True, "first"))
    client.wait_for_service("/svc", timeout=5)
    proxy = client.service_proxy("/svc", Trigger, persistent=True)
    assert proxy().message == "first"
    first.shutdown("restart")
    second = make_node("server_b")
    second.service("/svc", Trigger, lambda req: (True, "second"))
    client.wait_for_service("/svc", timeout=5)
    with pytest.raises(ServiceError, match="transport error"):
        proxy()  # the old connection is gone: this call fails, as in rospy
    assert proxy().message == "second"
    assert proxy().message == "second"


def test_fieldless_requests_are_fresh_default_instances(make_node) -> None:
    from std_srvs.srv import Trigger as GeneratedTrigger
    from std_srvs.srv import TriggerRequest, TriggerResponse

    server, client = make_node("server"), make_node("client")
    seen: list[object] = []

    def handler(req):
        seen.append(req)
        return TriggerResponse(True, f"call {len(seen)}")

    server.service("trigger", GeneratedTrigger, handler)
    client.wait_for_service("trigger", timeout=5)
    proxy = client.service_proxy("trigger", GeneratedTrigger, persistent=True)
    assert [proxy().message for _ in range(3)] == ["call 1", "call 2", "call 3"]
    assert all(type(req) is TriggerRequest for req in seen)
    assert len({id(req) for req in seen}) == 3  # never one shared instance


def test_rospy_proxy_call_is_direct_and_subclass_overrides_still_apply(make_node, monkeypatch) -> None:
    import rospy
    import rospy.service

    server = make_node("server")
    server.service("add", AddTwoInts, lambda r: r.a + r.b)
    # no init_node: the proxies talk to this test's master as /unnamed, from a fresh context
    monkeypatch.setenv("ROS_MASTER_URI", server.master_uri)
    monkeypatch.setattr(rospy.core._process, "unnamed", None)

    class Doubling(rospy.ServiceProxy):
        def call(self, *args, **kwds):
            return 2 * super().call(*args, **kwds).sum

    plain = rospy.ServiceProxy("/add", AddTwoInts, persistent=True)
    doubling = Doubling("/add", AddTwoInts, persistent=True)
    try:
        assert rospy.ServiceProxy.__call__ is rospy.ServiceProxy.call
        assert plain(2, 3).sum == 5
        assert doubling(2, 3) == 10  # proxy(...) reaches the subclass's call()
    finally:
        plain.close()
        doubling.close()
