"""Which host name a process advertises in its URIs (ROS 1's ROS_HOSTNAME / ROS_IP rules).

ROS_HOSTNAME wins over ROS_IP; without either, ROS 1 advertises the machine's host name. A value with
a scheme or port is a user mistake ROS 1 rejects; we reject it the same way, naming the variable.
"""

from __future__ import annotations

import os
import socket
from collections.abc import Mapping

from ninjemys.errors import NinjemysError


def advertised_host(env: Mapping[str, str] | None = None) -> str:
    """The host part peers should use to reach this process."""
    env = os.environ if env is None else env
    for var in ("ROS_HOSTNAME", "ROS_IP"):
        value = env.get(var, "").strip()
        if value:
            if "://" in value or (":" in value and var == "ROS_HOSTNAME"):
                raise NinjemysError(f"{var}={value!r}: give a bare host name or address (no scheme or port)")
            return value
    return socket.gethostname() or "localhost"


def master_uri(env: Mapping[str, str] | None = None) -> str:
    """ROS_MASTER_URI, or ROS 1's default ``http://localhost:11311/``."""
    env = os.environ if env is None else env
    return env.get("ROS_MASTER_URI", "").strip() or "http://localhost:11311/"


def split_uri(uri: str) -> tuple[str, int]:
    """``(host, port)`` of an ``http://host:port/`` (or ``rosrpc://``) URI; ``ValueError`` if it has none."""
    rest = uri.split("://", 1)[1] if "://" in uri else uri
    hostport = rest.split("/", 1)[0]
    if hostport.startswith("["):
        host, _, port = hostport[1:].partition("]:")
    else:
        host, _, port = hostport.rpartition(":")
    if not host or not port.isdigit():
        raise ValueError(f"URI {uri!r} has no host:port")
    return host, int(port)


def lookup_host(host: str) -> str | bytes:
    """``host`` as ``socket.getaddrinfo`` takes it cheapest: ASCII names as bytes.

    Given a ``str``, getaddrinfo encodes it with the ``idna`` codec, whose first use imports
    ``encodings.idna``, ``stringprep`` and ``unicodedata``: milliseconds of every node's start-up
    spent on host names that are plain ASCII (``localhost``) in practice.
    """
    return host.encode("ascii") if host.isascii() else host
