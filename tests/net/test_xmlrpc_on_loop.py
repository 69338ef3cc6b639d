"""The XML-RPC server and client on the node runtime's loop (the master runs them on asyncio; its
tests cover that side): calls, keep-alive, awaitable methods, garbage, timeouts, half-closed peers."""

from __future__ import annotations

import socket
import threading
import time
import xmlrpc.client
from collections.abc import Iterator
from typing import Any

import pytest

from ninjemys.errors import ProtocolError, TimeoutError_
from ninjemys.net import loop as nloop
from ninjemys.net import xmlrpc_client
from ninjemys.net.loop import Loop
from ninjemys.net.xmlrpc_server import XmlRpcServer


class Handler:
    def echo(self, value: Any) -> Any:
        return value

    async def later(self, value: int) -> int:
        await nloop.sleep(0.01)
        return value + 1

    def big(self, n: int) -> str:
        return "y" * n

    def broken(self) -> None:
        raise RuntimeError("handler bug")


@pytest.fixture
def served() -> Iterator[tuple[Loop, XmlRpcServer]]:
    lp = Loop()
    thread = threading.Thread(target=lp.run_forever, daemon=True)
    thread.start()
    server = XmlRpcServer(Handler(), "127.0.0.1", 0, advertise="127.0.0.1", idle_timeout=0.3)
    try:
        lp.run_coroutine_threadsafe(server.start()).result(5)
        yield lp, server
    finally:
        done = threading.Event()

        def close() -> None:
            server.close()
            done.set()

        lp.call_soon_threadsafe(close)
        done.wait(5)
        lp.call_soon_threadsafe(lp.stop)
        thread.join(5)
        lp.shutdown_tasks(0.5)
        lp.close()


def test_stdlib_client_calls_sync_and_async_methods_on_one_connection(
    served: tuple[Loop, XmlRpcServer],
) -> None:
    _, server = served
    proxy = xmlrpc.client.ServerProxy(server.uri)
    assert proxy.echo([1, "two", {"three": 3.0}]) == [1, "two", {"three": 3.0}]
    assert proxy.later(41) == 42
    assert len(proxy.big(1_000_000)) == 1_000_000  # an answer bigger than the socket buffer
    with pytest.raises(xmlrpc.client.Fault, match="handler bug"):
        proxy.broken()
    with pytest.raises(xmlrpc.client.Fault, match="not supported"):
        proxy.nothing_here()
    multi = xmlrpc.client.MultiCall(proxy)
    multi.echo(1)
    multi.later(1)
    assert list(multi()) == [1, 2]


def test_our_client_on_our_loop(served: tuple[Loop, XmlRpcServer]) -> None:
    lp, server = served
    assert lp.run_coroutine_threadsafe(xmlrpc_client.call(server.uri, "later", (9,))).result(5) == 10
    with pytest.raises(ProtocolError):
        lp.run_coroutine_threadsafe(xmlrpc_client.call(server.uri, "broken", ())).result(5)


def test_our_client_deadline_against_a_silent_peer(served: tuple[Loop, XmlRpcServer]) -> None:
    lp, _ = served
    silent = socket.socket()
    silent.bind(("127.0.0.1", 0))
    silent.listen(1)  # accepts the TCP handshake, never answers
    try:
        uri = f"http://127.0.0.1:{silent.getsockname()[1]}/"
        start = time.monotonic()
        with pytest.raises(TimeoutError_, match="no answer within"):
            lp.run_coroutine_threadsafe(xmlrpc_client.call(uri, "echo", (1,), timeout=0.2)).result(5)
        assert time.monotonic() - start < 3
    finally:
        silent.close()


def _raw(server: XmlRpcServer, data: bytes, half_close: bool = False) -> bytes:
    with socket.create_connection(("127.0.0.1", server.port), timeout=5) as sock:
        sock.sendall(data)
        if half_close:
            sock.shutdown(socket.SHUT_WR)
        chunks = []
        while True:
            chunk = sock.recv(65536)
            if not chunk:
                return b"".join(chunks)
            chunks.append(chunk)


def test_garbage_gets_400_and_the_server_keeps_serving(served: tuple[Loop, XmlRpcServer]) -> None:
    _, server = served
    reply = _raw(server, b"\x00\x01garbage that is not HTTP\r\n\r\n")
    assert reply.startswith(b"HTTP/1.1 400")
    assert xmlrpc.client.ServerProxy(server.uri).echo("still here") == "still here"


def test_a_half_closed_peer_still_gets_its_answer(served: tuple[Loop, XmlRpcServer]) -> None:
    _, server = served
    body = xmlrpc.client.dumps((7,), "later").encode()
    request = (
        b"POST / HTTP/1.1\r\nHost: x\r\nContent-Type: text/xml\r\nContent-Length: %d\r\n\r\n" % len(body)
        + body
    )
    reply = _raw(server, request, half_close=True)  # the server must answer, then close
    assert reply.startswith(b"HTTP/1.1 200") and b"<int>8</int>" in reply


def test_idle_connection_is_closed(served: tuple[Loop, XmlRpcServer]) -> None:
    _, server = served
    with socket.create_connection(("127.0.0.1", server.port), timeout=5) as sock:
        start = time.monotonic()
        assert sock.recv(10) == b""  # closed by the server's idle clock (0.3 s here)
        assert time.monotonic() - start < 4
    deadline = time.monotonic() + 2
    while server._connections and time.monotonic() < deadline:
        time.sleep(0.01)
    assert not server._connections
