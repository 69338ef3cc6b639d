"""An event-loop XML-RPC client with a hard deadline per call.

The master uses it to notify nodes (``publisherUpdate``, ``paramUpdate``, ``shutdown``): a node that
is dead, slow or hostile costs one timed-out task and a log line, never a blocked thread
(ros/ros_comm#1555). The deadline covers everything: name lookup, connect, send, and reading the
whole response.

It runs on the caller's loop, asyncio's (the master) or :class:`ninjemys.net.loop.Loop` (nodes), and
works on bare non-blocking sockets (``loop.sock_*``) rather than streams: a call is one socket and
a few syscalls, which matters when the master fans out thousands of notifications. Host names are
resolved once and cached for a minute (``localhost`` would otherwise cost a thread-pool round trip
per call).
"""

from __future__ import annotations

import socket
import time

from ninjemys.errors import ProtocolError, TimeoutError_
from ninjemys.net import auth
from ninjemys.net.addresses import split_uri
from ninjemys.net.loop import get_running_loop
from ninjemys.net.loop import timeout as deadline
from ninjemys.wire import xmlrpc as wire

TYPE_CHECKING = False  # importing typing costs ~7 ms of every node's start-up; checkers set it
if TYPE_CHECKING:
    from typing import Any

#: Responses from nodes are small; a peer that sends more is not a ROS node.
MAX_RESPONSE_BYTES = 16 * 1024 * 1024
_RESOLVE_TTL = 60.0
_resolved: dict[tuple[str, int], tuple[float, int, tuple[Any, ...]]] = {}


async def call(uri: str, method: str, params: tuple[Any, ...] | list[Any], timeout: float = 10.0) -> Any:
    """Call ``method`` at ``uri`` and return the response value.

    Raises ``TimeoutError_`` after ``timeout`` seconds, ``OSError`` if the peer cannot be reached
    (``ConnectionRefusedError`` when nothing listens), ``ProtocolError`` if it answers with something
    that is not XML-RPC, and ``wire.Fault`` (a ``ProtocolError``) for a fault response.
    """
    try:
        host, port = split_uri(uri)
    except ValueError as exc:
        raise ProtocolError(str(exc)) from None
    body = wire.dump_call(method, params)
    caller = params[0] if params and isinstance(params[0], str) else ""
    signature = auth.http_header_line(body, caller)
    request = wire.http_request(host, port, body, keep_alive=False, extra_headers=signature)
    try:
        async with deadline(timeout):
            return await _exchange(host, port, request)
    except TimeoutError:
        raise TimeoutError_(f"XML-RPC {method} to {uri}: no answer within {timeout:g} s") from None


async def _address(loop: Any, host: str, port: int) -> tuple[int, tuple[Any, ...]]:
    key = (host, port)
    cached = _resolved.get(key)
    now = time.monotonic()
    if cached is not None and now - cached[0] < _RESOLVE_TTL:
        return cached[1], cached[2]
    infos = await loop.getaddrinfo(host, port, type=socket.SOCK_STREAM)
    if not infos:
        raise OSError(f"cannot resolve {host}")
    family, _, _, _, address = infos[0]
    if len(_resolved) > 4096:
        _resolved.clear()
    _resolved[key] = (now, family, address)
    return family, address


async def _exchange(host: str, port: int, request: bytes) -> Any:
    loop = get_running_loop()
    family, address = await _address(loop, host, port)
    sock = socket.socket(family, socket.SOCK_STREAM)
    try:
        sock.setblocking(False)
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        await loop.sock_connect(sock, address)
        await loop.sock_sendall(sock, request)
        parser = wire.HttpResponseParser(max_body=MAX_RESPONSE_BYTES)
        while True:
            data = await loop.sock_recv(sock, 65536)
            if not data:
                raise ProtocolError(f"XML-RPC peer {host}:{port} closed the connection before answering")
            messages = parser.feed(data)
            if messages:
                response = messages[0]
                if response.start[1] != "200":
                    raise ProtocolError(f"XML-RPC peer {host}:{port} answered HTTP {response.start[1]}")
                return wire.parse_response(response.body)
    finally:
        sock.close()
