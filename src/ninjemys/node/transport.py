"""Socket plumbing shared by topics and services: header exchange and the node's TCPROS server.

Between processes on one host (unless ``NINJEMYS_UNIXROS=0``) the same TCPROS streams run over a
Unix-domain socket (``UNIXROS``):
the node's server also listens on the abstract name ``@ninjemys-tcpros-<port>`` (Linux; abstract
names vanish with the socket, so a crashed node leaves nothing behind). Subscribers ask for it in
``requestTopic`` before TCPROS, with this host's identity (boot id and network namespace), and the
publisher grants it only to the same host; service clients whose URI is a local address try the
name of the URI's port first. Peers that do not know it (rospy, roscpp) get plain TCPROS.

All coroutines here run on the runtime loop. Every read has a deadline and every length is checked
before anything is allocated, so a silent, slow or lying peer costs one log line and one closed
socket, never a hung or crashed node.
"""

from __future__ import annotations

import logging
import os
import socket
import sys
from collections.abc import Callable

from ninjemys.errors import ProtocolError
from ninjemys.net import auth
from ninjemys.net.loop import get_running_loop, sleep
from ninjemys.net.loop import timeout as deadline
from ninjemys.wire import headers

TYPE_CHECKING = False  # importing typing costs ~7 ms of every node's start-up; checkers set it
if TYPE_CHECKING:
    from typing import Any

_log = logging.getLogger(__name__)

#: How long a peer may take to send its connection header.
HEADER_TIMEOUT = 10.0

#: the transport names getBusInfo reports (ROS 1's is "TCPROS")
TCPROS, UNIXROS = "TCPROS", "UNIXROS"

_identity: str | None = None


def local_transport_enabled() -> bool:
    """Unix-domain sockets between processes of one host: Linux (abstract names), unless
    ``NINJEMYS_UNIXROS=0`` asks for TCP everywhere (to compare, or to debug with tcpdump). (It was
    opt-in while a flat-out publisher could starve a subscriber of its own process over it: see
    ``topics._LAG_YIELD``.)"""
    return sys.platform.startswith("linux") and os.environ.get("NINJEMYS_UNIXROS", "1") != "0"


def host_identity() -> str:
    """This host as a Unix socket sees it: the boot id and the network namespace (abstract socket
    names are per namespace, like TCP ports). Two processes may use UNIXROS iff these are equal."""
    global _identity
    if _identity is None:
        try:
            with open("/proc/sys/kernel/random/boot_id") as f:
                boot = f.read().strip()
            netns = os.stat("/proc/self/ns/net").st_ino
            _identity = f"{boot}/{netns}"
        except OSError:
            _identity = ""
    return _identity


def unix_address(port: int) -> str:
    """The abstract socket name of the node whose TCPROS port is ``port`` (``@`` as ``ss`` shows it)."""
    return f"@ninjemys-tcpros-{port}"


def unix_sockaddr(address: str) -> str | bytes:
    """``@name`` (abstract) or a filesystem path, as ``socket.connect`` takes it."""
    return b"\0" + address[1:].encode() if address.startswith("@") else address


def transport_of(sock: socket.socket) -> str:
    return UNIXROS if sock.family == socket.AF_UNIX else TCPROS


def unread_probe(sock: socket.socket) -> Callable[[], int] | None:
    """For a Unix stream socket, a function giving the bytes written to it that the peer has not read
    yet (the ``SIOCOUTQ`` ioctl: on Linux, what the kernel still holds for the reader); None elsewhere
    (on TCP it counts unacknowledged bytes, which on loopback says nothing about the reader).

    A publisher asks it in a burst: a subscriber that has read everything is waiting, so the next
    frame goes out at once; one that has not is busy, so frames can wait to go out together (Nagle's
    rule, with "read" for "acknowledged"). Imported on first use: most sockets never ask.
    """
    if sock.family != socket.AF_UNIX:
        return None
    try:
        import fcntl
        import struct
        import termios

        request = termios.TIOCOUTQ  # == SIOCOUTQ
        fd = sock.fileno()
        unpack = struct.Struct("i").unpack
        fcntl.ioctl(fd, request, b"\0\0\0\0")  # works here, or not at all
    except (ImportError, AttributeError, OSError):
        return None

    def unread() -> int:
        try:
            return int(unpack(fcntl.ioctl(fd, request, b"\0\0\0\0"))[0])
        except OSError:
            return 0

    return unread


def tune(sock: socket.socket, nodelay: bool = True) -> None:
    """Non-blocking, TCP_NODELAY as asked, keepalive on (a vanished peer is eventually noticed)."""
    sock.setblocking(False)
    if sock.family == socket.AF_UNIX:
        return  # no Nagle and no keepalive on a Unix socket: the kernel ends it with the peer
    try:
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1 if nodelay else 0)
        sock.setsockopt(socket.SOL_SOCKET, socket.SO_KEEPALIVE, 1)
    except OSError:
        pass


def close_quietly(sock: socket.socket) -> None:
    try:
        sock.close()
    except OSError:
        pass


async def read_exact(sock: socket.socket, n: int) -> bytearray:
    """Exactly ``n`` bytes from a non-blocking socket; ProtocolError if the peer closes first."""
    loop = get_running_loop()
    buf = bytearray(n)
    view = memoryview(buf)
    got = 0
    while got < n:
        k = await loop.sock_recv_into(sock, view[got:])
        if k == 0:
            raise ProtocolError(f"peer closed the connection after {got} of {n} bytes")
        got += k
    return buf


async def read_header(sock: socket.socket, timeout: float = HEADER_TIMEOUT) -> dict[str, str]:
    """Read and decode one connection header, with a deadline."""
    async with deadline(timeout):
        prefix = await read_exact(sock, 4)
        if bytes(prefix) in _HTTP_STARTS:
            # ports are reused: a peer still holding a dead node's XML-RPC URI can land here
            raise ProtocolError("an HTTP request arrived on the TCPROS port (a stale XML-RPC URI?)")
        length = headers.header_length(prefix)
        return headers.decode_header(await read_exact(sock, length))


_HTTP_STARTS = frozenset({b"POST", b"GET ", b"HEAD", b"PUT ", b"HTTP"})


async def write_all(sock: socket.socket, data: bytes) -> None:
    await get_running_loop().sock_sendall(sock, data)


async def connect(sock: socket.socket, address: tuple[Any, ...], timeout: float) -> None:
    """Connect a non-blocking socket (host names resolved off the loop); ``TimeoutError`` after ``timeout``."""
    async with deadline(timeout):
        await get_running_loop().sock_connect(sock, address)


async def send_error_header(sock: socket.socket, text: str) -> None:
    """Tell the peer why we refuse (``error=``), as roscpp/rospy do, then the caller closes."""
    try:
        async with deadline(2.0):
            await write_all(sock, headers.encode_header({"error": text}))
    except (OSError, TimeoutError):
        pass


def peer_name(sock: socket.socket) -> str:
    if sock.family == socket.AF_UNIX:
        return "a local process (UNIXROS)"
    try:
        host, port = sock.getpeername()[:2]
        return f"{host}:{port}"
    except OSError:
        return "?"


class TcprosServer:
    """The node's one TCPROS listening socket; routes each inbound connection by its header.

    ``on_topic(sock, header)`` / ``on_service(sock, header)`` are coroutines that take ownership of
    the socket. Headers with neither ``topic`` nor ``service`` get an error header and are closed.
    """

    def __init__(self, on_topic: Callable, on_service: Callable, host: str = "0.0.0.0") -> None:
        self._on_topic = on_topic
        self._on_service = on_service
        self._sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        self._sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self._sock.bind((host, 0))
        self._sock.listen(128)
        self._sock.setblocking(False)
        self.port: int = self._sock.getsockname()[1]
        self._tasks: list[Any] = []
        self._conns: set[Any] = set()
        #: the UNIXROS listener's address, or None (not Linux, disabled, or the name was taken)
        self.unix_address: str | None = None
        self._unix: socket.socket | None = None
        if local_transport_enabled():
            unix = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
            try:
                unix.bind(unix_sockaddr(unix_address(self.port)))
                unix.listen(128)
                unix.setblocking(False)
                self._unix, self.unix_address = unix, unix_address(self.port)
            except OSError as exc:
                _log.info("UNIXROS unavailable (%s): TCPROS only", exc)
                close_quietly(unix)

    def start(self) -> None:
        """Begin accepting (call on the loop)."""
        loop = get_running_loop()
        self._tasks = [loop.create_task(self._accept_loop(self._sock))]
        if self._unix is not None:
            self._tasks.append(loop.create_task(self._accept_loop(self._unix)))

    async def _accept_loop(self, listener: socket.socket) -> None:
        loop = get_running_loop()
        while True:
            try:
                conn, _ = await loop.sock_accept(listener)
            except OSError as exc:
                if listener.fileno() < 0:
                    return
                _log.warning("TCPROS accept failed: %s", exc)
                await sleep(0.05)
                continue
            tune(conn)
            task = loop.create_task(self._route(conn))
            self._conns.add(task)
            task.add_done_callback(self._conns.discard)

    async def _route(self, sock: socket.socket) -> None:
        try:
            header = await read_header(sock)
        except (ProtocolError, OSError, TimeoutError) as exc:
            why = "no connection header within the deadline" if isinstance(exc, TimeoutError) else exc
            _log.warning("TCPROS: dropped inbound connection from %s: %s", peer_name(sock), why)
            close_quietly(sock)
            return
        refused = auth.check_fields(header)
        if refused is not None:
            who = header.get("callerid", peer_name(sock))
            _log.warning("TCPROS: refused %s (%s): authentication failed: %s", who,
                         header.get("topic") or header.get("service") or "?", refused)  # fmt: skip
            await send_error_header(sock, f"authentication failed: {refused}")
            close_quietly(sock)
            return
        try:
            if "topic" in header:
                await self._on_topic(sock, header)
            elif "service" in header:
                await self._on_service(sock, header)
            else:
                _log.warning("TCPROS: connection from %s names no topic or service", peer_name(sock))
                await send_error_header(sock, "no topic or service name detected")
                close_quietly(sock)
        except Exception as exc:  # a handler bug must not kill the accept loop
            _log.error("TCPROS: error handling connection from %s: %s", peer_name(sock), exc)
            close_quietly(sock)

    def close(self) -> None:
        """Stop accepting (call on the loop)."""
        for task in self._tasks:
            task.cancel()
        for task in list(self._conns):
            task.cancel()
        close_quietly(self._sock)
        if self._unix is not None:
            close_quietly(self._unix)
