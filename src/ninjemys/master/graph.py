"""The ROS graph as the tools read it: one snapshot, a node's slave API, and the one way to ping.

:class:`~ninjemys.master.snapshot.GraphSnapshot` (re-exported here) is the master's answers indexed
once. :func:`ping_node` is ``rosnode ping``'s loop (getPid round trips, ROS 1's lines for each way it fails,
a node that came back on a new port followed through the master), shared by the ``rosnode`` command and
the ``rosnode`` facade's ``rosnode_ping``: each passes its own way to look the node up and to print.

"""

from __future__ import annotations

import re
import socket
import time
from collections.abc import Callable
from typing import Any
from urllib.parse import urlparse

from ninjemys.errors import MasterError, MasterUnreachable
from ninjemys.master.client import MasterClient
from ninjemys.master.snapshot import GraphSnapshot

__all__ = [
    "CONNECTION_INFO",
    "PING_TIMEOUT",
    "GraphSnapshot",
    "bus_info",
    "node_api",
    "ping",
    "ping_failure",
    "ping_node",
    "slave",
]

#: getBusInfo's optional 7th element, as rospy/roscpp write it
CONNECTION_INFO = re.compile(r"\w+ connection on port (\d+) to \[(.*) on socket (\d+)\]")

#: ``rosnode ping``'s timeout for one getPid, as ROS 1's
PING_TIMEOUT = 3.0

# ------------------------------------------------------------------------------------ slave API


def node_api(master: MasterClient, node: str) -> str | None:
    """The node's XML-RPC URI, or None when the master does not know it."""
    try:
        return master.lookup_node(node)
    except MasterError as exc:
        if isinstance(exc, MasterUnreachable):
            raise
        return None


def slave(uri: str, caller_id: str, timeout: float = PING_TIMEOUT) -> MasterClient:
    """A client for a node's slave API (the same keep-alive XML-RPC client the master uses)."""
    return MasterClient(uri, caller_id=caller_id, timeout=timeout)


def ping(uri: str, caller_id: str, timeout: float = PING_TIMEOUT) -> float:
    """One getPid round trip in milliseconds; raises MasterUnreachable/MasterError on failure."""
    client = slave(uri, caller_id, timeout)
    try:
        start = time.perf_counter()
        client.call("getPid")
        return (time.perf_counter() - start) * 1000.0
    finally:
        client.close()


def bus_info(uri: str, caller_id: str, timeout: float = 5.0) -> tuple[int, list[list[Any]]]:
    """(pid, getBusInfo rows) of a node."""
    client = slave(uri, caller_id, timeout)
    try:
        return client.call("getPid"), client.call("getBusInfo")
    finally:
        client.close()


# ------------------------------------------------------------------------------------ rosnode ping

#: how one getPid failed, as ``rosnode ping`` tells them apart
TIMED_OUT, UNKNOWN_HOST, REFUSED, FAILED = "timed out", "unknown host", "refused", "failed"


def ping_failure(uri: str, exc: MasterError) -> str:
    """Which of ROS 1's ping failures ``exc`` (from :func:`ping`) is."""
    if not isinstance(exc, MasterUnreachable):
        return FAILED
    if "timed out" in str(exc):
        return TIMED_OUT
    try:
        socket.getaddrinfo(urlparse(uri).hostname, 0)
    except OSError:
        return UNKNOWN_HOST
    return REFUSED


def ping_node(
    node: str,
    lookup: Callable[[str, bool], str | None],
    caller_id: str,
    max_count: int | None = None,
    verbose: bool = False,
    out: Callable[[str], None] = print,
    err: Callable[[str], None] = print,
    sleep: Callable[[float], None] = time.sleep,
) -> bool:
    """``rosnode ping``: getPid ``max_count`` times (forever if None), a second apart; True if the node
    answered. ``lookup(node, skip_cache)`` gives its URI (None: unknown); when the connection is refused
    the URI is looked up again and, if the node moved, followed. ROS 1's lines go to ``out``/``err``.
    Ctrl-C ends the loop (with the average, as ROS 1 prints it)."""
    uri = lookup(node, False)
    if not uri:
        err(f"cannot ping [{node}]: unknown node")
        return False
    if verbose:
        out(f"pinging {node} with a timeout of {PING_TIMEOUT}s")
    count, total = 0, 0.0
    try:
        while True:
            try:
                ms = ping(uri, caller_id, PING_TIMEOUT)
            except MasterError as exc:
                failure = ping_failure(uri, exc)
                if failure == REFUSED:
                    moved = lookup(node, True)
                    if not moved:
                        err(f"cannot ping [{node}]: unknown node")
                        return False
                    if moved != uri:
                        if verbose:
                            out(f"node url has changed from [{uri}] to [{moved}], retrying to ping")
                        uri = moved
                        continue
                    err(f"ERROR: connection refused to [{uri}]")
                elif failure == TIMED_OUT:
                    err(f"connection to [{node}] timed out")
                elif failure == UNKNOWN_HOST:
                    err(f"ERROR: Unknown host [{urlparse(uri).hostname}] for node [{node}]")
                else:
                    err(f"connection to [{node}] failed")
                return False
            count += 1
            total += ms
            if verbose:
                out(f"xmlrpc reply from {uri}\ttime={ms:f}ms")
            if max_count and count >= max_count:
                break
            sleep(1.0)
    except KeyboardInterrupt:
        pass
    if verbose and count > 1:
        out(f"ping average: {total / count:f}ms")
    return True
