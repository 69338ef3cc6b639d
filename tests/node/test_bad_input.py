"""Bad input on TCPROS: one clear log line, the connection dropped, every other connection served."""

from __future__ import annotations

import logging
import socket
import struct
import threading
import time
import xmlrpc.client
import xmlrpc.server
from collections.abc import Iterator

import pytest
from node_msgs import String

from ninjemys.testing import wait_until
from ninjemys.wire import headers
from ninjemys.wire.tcpros import frame


@pytest.fixture
def pair(make_node):
    """A talker and a listener already exchanging messages on /chatter."""
    talker, listener = make_node("talker"), make_node("listener")
    got: list[str] = []
    listener.subscriber("chatter", String, lambda m: got.append(m.data))
    pub = talker.publisher("chatter", String)
    assert wait_until(lambda: pub.get_num_connections() == 1)
    return talker, listener, pub, got


def _still_works(pub, got: list[str], tag: str) -> None:
    pub.publish(String(tag))
    assert wait_until(lambda: tag in got), f"{tag} never arrived: {got}"


def _send_to_publisher(talker, data: bytes) -> bytes:
    with socket.create_connection(("127.0.0.1", talker.tcpros_port), timeout=5) as sock:
        try:
            sock.sendall(data)
            sock.shutdown(socket.SHUT_WR)
        except OSError:
            pass  # the node may already have refused and closed: that is the point
        out = b""
        try:
            while chunk := sock.recv(65536):
                out += chunk
        except OSError:
            pass
        return out


def _logged(caplog, text: str) -> list[logging.LogRecord]:
    return [r for r in caplog.records if text in r.getMessage() and r.name.startswith("ninjemys")]


@pytest.mark.parametrize(
    ("data", "expected"),
    [
        (b"\xff\xff\xff\xff" + b"x" * 16, "exceeds"),
        (struct.pack("<I", 12) + struct.pack("<I", 100) + b"topic=/x", "claims 100 bytes"),
        (struct.pack("<I", 8) + struct.pack("<I", 4) + b"junk", "no name=value"),
        (struct.pack("<I", 50) + b"short", "closed the connection"),
        (b"POST /RPC2 HTTP/1.1\r\nContent-Length: 0\r\n\r\n", "an HTTP request arrived"),
    ],
    ids=["oversized-header", "field-overruns", "no-equals", "disconnect-mid-header", "http-to-tcpros-port"],
)
def test_garbage_headers_to_publisher(pair, caplog, data: bytes, expected: str) -> None:
    talker, _listener, pub, got = pair
    caplog.set_level(logging.INFO)
    _send_to_publisher(talker, data)
    assert wait_until(lambda: _logged(caplog, expected)), [r.getMessage() for r in caplog.records]
    assert len(_logged(caplog, expected)) == 1
    _still_works(pub, got, expected)


def test_wrong_md5_from_raw_socket_gets_error_header(pair, caplog) -> None:
    talker, _listener, pub, got = pair
    reply = _send_to_publisher(
        talker,
        headers.encode_header(
            {"callerid": "/evil", "topic": "/chatter", "md5sum": "0" * 32, "type": "std_msgs/String"}
        ),
    )
    assert "error" in headers.decode_header(reply[4:])
    assert pub.get_num_connections() == 1
    _still_works(pub, got, "after md5")


def test_header_without_topic_or_service(pair, caplog) -> None:
    talker, _listener, pub, got = pair
    reply = _send_to_publisher(talker, headers.encode_header({"callerid": "/x"}))
    assert headers.decode_header(reply[4:])["error"] == "no topic or service name detected"
    _still_works(pub, got, "after routing error")


class FakePublisher:
    """A slave API answering requestTopic, and a TCPROS port that misbehaves after the header."""

    def __init__(self, behaviour: bytes) -> None:
        self.behaviour = behaviour
        self.listener = socket.create_server(("127.0.0.1", 0))
        self.port = self.listener.getsockname()[1]
        self.rpc = xmlrpc.server.SimpleXMLRPCServer(("127.0.0.1", 0), logRequests=False, allow_none=False)
        self.rpc.register_function(
            lambda caller, topic, protos: [1, "ready", ["TCPROS", "127.0.0.1", self.port]], "requestTopic"
        )
        self.uri = f"http://127.0.0.1:{self.rpc.server_address[1]}/"
        self.threads = [
            threading.Thread(target=self.rpc.serve_forever, daemon=True),
            threading.Thread(target=self._serve_tcpros, daemon=True),
        ]
        for t in self.threads:
            t.start()

    def _serve_tcpros(self) -> None:
        conn, _ = self.listener.accept()
        with conn:
            length = struct.unpack("<I", conn.recv(4))[0]
            while length > 0:
                length -= len(conn.recv(length))
            conn.sendall(
                headers.encode_header(
                    {
                        "callerid": "/fake",
                        "topic": "/chatter",
                        "type": "std_msgs/String",
                        "md5sum": String._md5sum,
                    }
                )
            )
            conn.sendall(self.behaviour)
            time.sleep(0.2)

    def close(self) -> None:
        self.rpc.shutdown()
        self.rpc.server_close()
        self.listener.close()


@pytest.fixture
def fake_publisher(request) -> Iterator[FakePublisher]:
    fake = FakePublisher(request.param)
    try:
        yield fake
    finally:
        fake.close()


@pytest.mark.parametrize(
    ("fake_publisher", "expected"),
    [
        (b"\xff\xff\xff\x7f", "exceeds"),
        (frame(b"\x05\x00\x00\x00hello")[:7], "mid-message"),
        (struct.pack("<I", 3) + b"abc", "cannot deserialize"),
    ],
    indirect=["fake_publisher"],
    ids=["oversized-length", "disconnect-mid-message", "undecodable-body"],
)
def test_misbehaving_publisher_is_dropped(pair, caplog, fake_publisher: FakePublisher, expected: str) -> None:
    talker, listener, pub, got = pair
    caplog.set_level(logging.INFO)
    api = xmlrpc.client.ServerProxy(listener.uri)
    assert api.publisherUpdate("/master", "/chatter", [talker.uri, fake_publisher.uri])[0] == 1
    assert wait_until(lambda: _logged(caplog, expected)), [r.getMessage() for r in caplog.records]
    assert len(_logged(caplog, expected)) == 1
    _still_works(pub, got, expected)


def test_a_subscriber_gone_before_its_hello_leaves_the_node_working(pair) -> None:
    """A subscriber that hangs up between its header and the publisher's answer: the hello's write
    fails while the publication's lock is held, and the connection's end is reported after it (it
    was reported inline, on the I/O thread, waiting for that same lock: the thread hung and with it
    every later call of the process)."""
    talker, _listener, pub, got = pair
    publication = talker._publications["/chatter"]
    ours, theirs = socket.socketpair()
    theirs.close()  # gone: the publisher's first write fails (EPIPE)
    ours.setblocking(False)
    header = {
        "callerid": "/gone",
        "topic": "/chatter",
        "type": String._type,
        "md5sum": String._md5sum,
    }
    talker.runtime.run(publication.accept(ours, header), timeout=5)
    assert wait_until(lambda: pub.get_num_connections() == 1)  # the dead one removed, the listener kept
    _still_works(pub, got, "after a subscriber that hung up")
