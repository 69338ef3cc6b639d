"""The master's XML-RPC server under hostile input: it answers, drops the offender, and keeps serving."""

from __future__ import annotations

import os
import socket
import threading
import time
import xmlrpc.client
from collections.abc import Iterator

import pytest

from ninjemys.master.client import MasterClient
from ninjemys.master.core import MasterThread
from ninjemys.net.addresses import split_uri


@pytest.fixture
def master() -> Iterator[str]:
    thread = MasterThread()
    uri = thread.start()
    try:
        yield uri
    finally:
        thread.stop()


def _connect(uri: str) -> socket.socket:
    host, port = split_uri(uri)
    sock = socket.create_connection((host, port), timeout=5)
    return sock


def _read_all(sock: socket.socket) -> bytes:
    chunks = []
    while True:
        try:
            data = sock.recv(65536)
        except (ConnectionResetError, TimeoutError):
            break
        if not data:
            break
        chunks.append(data)
    return b"".join(chunks)


def _still_serves(uri: str) -> None:
    assert MasterClient(uri, "/probe", timeout=5).get_pid() == os.getpid()


def test_random_bytes_get_400_and_close(master: str) -> None:
    sock = _connect(master)
    sock.sendall(os.urandom(4096) + b"\r\n\r\n")
    reply = _read_all(sock)
    assert reply.startswith(b"HTTP/1.1 400")
    _still_serves(master)


def test_malformed_xml_is_a_fault_and_connection_survives(master: str) -> None:
    sock = _connect(master)
    body = b"<methodCall><methodName>getPid</methodName><params><param><value><int>1"
    request = f"POST /RPC2 HTTP/1.1\r\nContent-Length: {len(body)}\r\n\r\n".encode() + body
    sock.sendall(request)
    reply = sock.recv(65536)
    assert reply.startswith(b"HTTP/1.1 200") and b"faultCode" in reply
    good = xmlrpc.client.dumps(("/a",), "getPid").encode()
    sock.sendall(f"POST /RPC2 HTTP/1.1\r\nContent-Length: {len(good)}\r\n\r\n".encode() + good)
    assert str(os.getpid()).encode() in sock.recv(65536)
    sock.close()


def test_huge_content_length_is_refused_without_buffering(master: str) -> None:
    sock = _connect(master)
    sock.sendall(b"POST /RPC2 HTTP/1.1\r\nContent-Length: 99999999999\r\n\r\n")
    assert _read_all(sock).startswith(b"HTTP/1.1 400")
    _still_serves(master)


def test_get_is_refused(master: str) -> None:
    sock = _connect(master)
    sock.sendall(b"GET / HTTP/1.1\r\nHost: x\r\n\r\n")
    assert _read_all(sock).startswith(b"HTTP/1.1 405")


def test_wrong_types_and_unknown_methods_answer(master: str) -> None:
    proxy = xmlrpc.client.ServerProxy(master)
    assert proxy.getParam("/a", {"not": "a string"})[0] == -1
    assert proxy.registerPublisher("/a", ["list"], 3, 4.5)[0] == -1
    assert proxy.getSystemState(42)[1] == "caller_id must be a string"
    with pytest.raises(xmlrpc.client.Fault):
        proxy.noSuchThing("/a")
    with pytest.raises(xmlrpc.client.Fault):
        proxy._dispatch("/a")
    _still_serves(master)


def test_slowloris_does_not_block_others(master: str) -> None:
    stalled = [_connect(master) for _ in range(20)]
    for sock in stalled:
        sock.sendall(b"POST /RPC2 HTTP/1.1\r\nContent-Length: 100\r\n\r\n<method")
    start = time.monotonic()
    for _ in range(20):
        _still_serves(master)
    assert time.monotonic() - start < 5
    for sock in stalled:
        sock.close()


def test_request_timeout_drops_a_stalled_request() -> None:
    from ninjemys.master.core import Master

    thread = MasterThread()
    thread.master = Master("127.0.0.1", 0, advertise="127.0.0.1")
    thread.master.server.request_timeout = 0.3
    uri = thread.start()
    try:
        sock = _connect(uri)
        sock.sendall(b"POST /RPC2 HTTP/1.1\r\nContent-Length: 10\r\n\r\nabc")
        sock.settimeout(5)
        assert _read_all(sock) == b""  # closed by the server, not by our 5 s timeout
    finally:
        thread.stop()


def test_keep_alive_serves_many_calls_on_one_connection(master: str) -> None:
    client = MasterClient(master, "/k")
    for i in range(50):
        client.set_param(f"/k{i}", i)
    assert client.get_param("/k49") == 49
    assert client._sock is not None


def test_multicall_as_roslaunch_uses_it(master: str) -> None:
    multi = xmlrpc.client.MultiCall(xmlrpc.client.ServerProxy(master))
    multi.setParam("/launch", "/a", 1)
    multi.setParam("/launch", "/b", "two")
    multi.getParam("/launch", "/b")
    results = list(multi())
    assert results == [[1, "parameter /a set", 0], [1, "parameter /b set", 0], [1, "Parameter [/b]", "two"]]


def test_concurrent_clients(master: str) -> None:
    errors: list[BaseException] = []

    def work(n: int) -> None:
        try:
            client = MasterClient(master, f"/w{n}")
            for i in range(30):
                client.register_publisher(f"/t{i}", "std_msgs/String", f"http://127.0.0.1:{n + 1}/")
        except BaseException as exc:
            errors.append(exc)

    threads = [threading.Thread(target=work, args=(n,)) for n in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors
    state = MasterClient(master, "/c").get_system_state()
    assert len(state[0]) == 30 and all(len(nodes) == 8 for _, nodes in state[0])
