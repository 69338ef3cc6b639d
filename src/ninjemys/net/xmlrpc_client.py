"""An asyncio XML-RPC client with a hard deadline per call.

The master uses it to notify nodes (``publisherUpdate``, ``paramUpdate``, ``shutdown``): a node that
is dead, slow or hostile costs one timed-out task and a log line, never a blocked thread
(ros/ros_comm#1555). The deadline covers everything: connect, send, and reading the whole response.
"""

from __future__ import annotations

import asyncio
from typing import Any

from ninjemys.errors import ProtocolError, TimeoutError_
from ninjemys.net.addresses import split_uri
from ninjemys.wire import xmlrpc as wire

#: Responses from nodes are small; a peer that sends more is not a ROS node.
MAX_RESPONSE_BYTES = 16 * 1024 * 1024


async def call(uri: str, method: str, params: tuple[Any, ...] | list[Any], timeout: float = 10.0) -> Any:
    """Call ``method`` at ``uri`` and return the response value.

    Raises ``TimeoutError_`` after ``timeout`` seconds, ``OSError`` if the peer cannot be reached,
    ``ProtocolError`` if it answers with something that is not XML-RPC, and ``wire.Fault`` (a
    ``ProtocolError``) for a fault response.
    """
    try:
        host, port = split_uri(uri)
    except ValueError as exc:
        raise ProtocolError(str(exc)) from None
    body = wire.dump_call(method, params)
    try:
        async with asyncio.timeout(timeout):
            return await _exchange(host, port, wire.http_request(host, port, body, keep_alive=False))
    except TimeoutError:
        raise TimeoutError_(f"XML-RPC {method} to {uri}: no answer within {timeout:g} s") from None


async def _exchange(host: str, port: int, request: bytes) -> Any:
    reader, writer = await asyncio.open_connection(host, port)
    try:
        writer.write(request)
        await writer.drain()
        parser = wire.HttpResponseParser(max_body=MAX_RESPONSE_BYTES)
        while True:
            data = await reader.read(65536)
            if not data:
                raise ProtocolError(f"XML-RPC peer {host}:{port} closed the connection before answering")
            messages = parser.feed(data)
            if messages:
                response = messages[0]
                if response.start[1] != "200":
                    raise ProtocolError(f"XML-RPC peer {host}:{port} answered HTTP {response.start[1]}")
                return wire.parse_response(response.body)
    finally:
        writer.close()
