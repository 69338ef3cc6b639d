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


def advertised_host_problem(host: str, env: Mapping[str, str] | None = None) -> str | None:
    """Why peers will not reach a node advertising ``host`` (it does not resolve here), or None.

    Blocking (a name lookup): call it off the I/O loop. A numeric address needs no lookup.
    """
    from ninjemys.net.loop import is_numeric_host  # the loop imports this module

    if is_numeric_host(host):
        return None
    try:
        # an ASCII name goes as bytes: a str would load the idna codec into every node (start-up cost)
        socket.getaddrinfo(host.encode("ascii") if host.isascii() else host, None)
    except (OSError, UnicodeError):
        env = os.environ if env is None else env
        source = "ROS_HOSTNAME" if env.get("ROS_HOSTNAME", "").strip() == host else "this machine's host name"
        return (
            f"{source} [{host}] does not resolve on this machine, so other nodes cannot connect to this "
            "node: set ROS_HOSTNAME to a name they can resolve, or ROS_IP to this machine's address"
        )
    return None


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


def is_local_address(host: str) -> bool:
    """True when ``host`` names this machine (loopback, its host name, or one of its addresses)."""
    if host in ("localhost", "127.0.0.1", "::1", "0.0.0.0", ""):
        return True
    try:
        if host in (socket.gethostname(), socket.getfqdn()):
            return True
        address = socket.gethostbyname(host)
    except OSError:
        return False
    if address.startswith("127."):
        return True
    try:
        return address in {info[4][0] for info in socket.getaddrinfo(socket.gethostname(), None)}
    except OSError:
        return False


def _ephemeral_range() -> tuple[int, int]:
    try:
        with open("/proc/sys/net/ipv4/ip_local_port_range", encoding="ascii") as f:
            low, high = f.read().split()
        return int(low), int(high)
    except (OSError, ValueError):
        return 32768, 60999


def free_port(host: str = "127.0.0.1") -> int:
    """A TCP port that was free a moment ago, chosen *below* the kernel's ephemeral range.

    For any master started a moment later: the tests (:mod:`ninjemys.testing` re-exports it) and the demo.

    Tests hand these ports to masters that start a moment later. A port from the ephemeral range
    (what binding to port 0 returns) can meanwhile be given by the kernel to any node that binds
    port 0 for its XML-RPC or TCPROS server; a test would then mistake that node for its master.
    """
    import random

    low, _ = _ephemeral_range()
    first, last = (20000, low - 1) if low > 21000 else (1024, low - 1)
    rng = random.Random()
    for _ in range(200):
        candidate = rng.randint(first, last)
        with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
            try:
                s.bind((host, candidate))
            except OSError:
                continue
            return candidate
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind((host, 0))
        return s.getsockname()[1]
