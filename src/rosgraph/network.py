"""rosgraph.network: the addresses a ROS 1 process advertises and binds, and the TCPROS connection
header (handshake) encoding, with ROS 1's names, over ninjemys.wire.headers."""

from __future__ import annotations

import fcntl
import logging
import os
import socket
import struct
import sys
from typing import Any
from urllib.parse import urlparse

from ninjemys.wire import headers as _headers

from .rosenv import ROS_HOSTNAME, ROS_IP, ROS_IPV6

SIOCGIFCONF = 0x8912
SIOCGIFADDR = 0x8915

logger = logging.getLogger("rosgraph.network")


class ROSHandshakeException(Exception):
    """A connection header that cannot be decoded."""


def parse_http_host_and_port(url: str) -> tuple[str, int]:
    """``(host, port)`` of an http URL, port 80 when absent; ValueError without scheme or host."""
    if not url:
        raise ValueError("not a valid URL")
    p = urlparse(url)
    if not p.scheme or not p.hostname:
        raise ValueError("not a valid URL")
    return p.hostname, p.port if p.port else 80


def _warn(msg: str) -> None:
    sys.stderr.write(msg + "\n")
    logger.warning(msg)


def get_address_override() -> str | None:
    """``__hostname:=``/``__ip:=``, else ROS_HOSTNAME, else ROS_IP (warning, not failing, on values
    ROS 1 warns about), else None."""
    for arg in sys.argv:
        if arg.startswith(("__hostname:=", "__ip:=")):
            parts = arg.split(":=")
            if len(parts) != 2:
                raise ValueError(f"invalid ROS command-line remapping argument '{arg}'")
            return parts[1]
    if ROS_HOSTNAME in os.environ:
        hostname = os.environ[ROS_HOSTNAME]
        if hostname == "":
            _warn("invalid ROS_HOSTNAME (an empty string)")
        else:
            url = urlparse(hostname)
            if url.scheme:
                _warn(
                    "invalid ROS_HOSTNAME (protocol "
                    + ("and port " if url.port else "")
                    + "should not be included)"
                )
            elif ":" in hostname:
                _warn("invalid ROS_HOSTNAME (port should not be included)")
        return hostname
    if ROS_IP in os.environ:
        ip = os.environ[ROS_IP]
        if ip == "":
            _warn("invalid ROS_IP (an empty string)")
        elif "://" in ip:
            _warn("invalid ROS_IP (protocol should not be included)")
        elif "." in ip and ip.rfind(":") > ip.rfind("."):
            _warn("invalid ROS_IP (port should not be included)")
        elif "." not in ip and ":" not in ip:
            _warn("invalid ROS_IP (must be a valid IPv4 or IPv6 address)")
        return ip
    return None


def use_ipv6() -> bool:
    """True when ROS_IPV6=on."""
    return os.environ.get(ROS_IPV6) == "on"


def _interface_v4(name: str) -> str | None:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        try:
            packed = fcntl.ioctl(s.fileno(), SIOCGIFADDR, struct.pack("256s", name.encode()[:15]))
        except OSError:
            return None  # an interface without an IPv4 address
    return socket.inet_ntoa(packed[20:24])


def _interface_v6() -> list[str]:
    try:
        with open("/proc/net/if_inet6") as f:
            rows = [line.split() for line in f]
    except OSError:
        return []
    return [
        socket.inet_ntop(socket.AF_INET6, bytes.fromhex(r[0]))
        + ("%" + r[5] if r[0].startswith("fe80") else "")
        for r in rows
    ]


_local_addrs: list[str] | None = None


def get_local_addresses() -> list[str]:
    """The machine's interface addresses (IPv4; IPv6 first, then IPv4, with ROS_IPV6=on), ignoring
    ROS_IP/ROS_HOSTNAME. Cached, as in ROS 1."""
    global _local_addrs
    if _local_addrs is None:
        v4 = [a for _i, name in socket.if_nameindex() if (a := _interface_v4(name))]
        _local_addrs = _interface_v6() + v4 if use_ipv6() else v4
    return _local_addrs


def is_local_address(hostname: str) -> bool:
    """True if ``hostname`` resolves to a loopback or one of this machine's addresses."""
    family = 0 if use_ipv6() else socket.AF_INET
    try:
        ips = [str(h[4][0]) for h in socket.getaddrinfo(hostname, 0, family, 0, socket.SOL_TCP)]
    except OSError:
        return False
    local = {"localhost", *get_local_addresses()}
    return any(ip.startswith("127.") or ip == "::1" for ip in ips) or bool(set(ips) & local)


def get_local_address() -> str:
    """The override if set, else the first non-loopback interface address, else loopback."""
    override = get_address_override()
    if override:
        return override
    addrs = get_local_addresses()
    if len(addrs) == 1:
        return addrs[0]
    for addr in addrs:
        if not addr.startswith("127.") and addr != "::1":
            return addr
    return "::1" if use_ipv6() else "127.0.0.1"


def get_bind_address(address: str | None = None) -> str:
    """Where servers bind: loopback when the advertised address is local-only, else every interface."""
    if address is None:
        address = get_address_override()
    if address and (address == "localhost" or address.startswith("127.") or address == "::1"):
        if use_ipv6():
            return "::1"
        return address if address.startswith("127.") else "127.0.0.1"
    return "::" if use_ipv6() else "0.0.0.0"  # noqa: S104  (ROS 1's default: every interface)


def get_host_name() -> str:
    """The host name for URIs: the override, else the machine's name, else an interface address."""
    hostname = get_address_override()
    if not hostname:
        try:
            hostname = socket.gethostname()
        except OSError:
            hostname = None
        if not hostname or hostname == "localhost" or hostname.startswith("127."):
            hostname = get_local_address()
    return hostname


def create_local_xmlrpc_uri(port: int) -> str:
    """``http://<get_host_name()>:<port>/``."""
    return f"http://{get_host_name()}:{port}/"


def decode_ros_handshake_header(header_str: bytes) -> dict[str, str]:
    """The fields of an encoded header (length prefix included; extra bytes after it are ignored)."""
    (size,) = struct.unpack("<I", header_str[0:4])
    if size + 4 > len(header_str):
        raise ROSHandshakeException(
            f"Incomplete header. Expected {size + 8} bytes but only have {len(header_str)}"
        )
    fields: dict[str, str] = {}
    start = 4
    while start < size + 4:
        (field_size,) = struct.unpack("<I", header_str[start : start + 4])
        if field_size == 0:
            raise ROSHandshakeException("Invalid 0-length handshake header field")
        start += field_size + 4
        if start > size + 4:
            raise ROSHandshakeException(f"Invalid line length in handshake header: {size + 4}")
        line = header_str[start - field_size : start].decode()
        key, eq, value = line.partition("=")
        if not eq:
            raise ROSHandshakeException(f"Invalid line in handshake header: [{line}]")
        fields[key.strip()] = value
    return fields


def read_ros_handshake_header(sock: socket.socket, b: Any, buff_size: int) -> dict[str, str]:
    """Read one header from blocking ``sock`` through buffer ``b`` (a BytesIO); bytes after it stay in ``b``."""
    while True:
        d = sock.recv(buff_size)
        if not d:
            raise ROSHandshakeException(
                "connection from sender terminated before handshake header received. "
                f"{b.tell()} bytes were received. Please check sender for additional details."
            )
        b.write(d)
        if b.tell() > 4:
            bval = b.getvalue()
            (size,) = struct.unpack("<I", bval[0:4])
            if b.tell() - 4 >= size:
                leftovers = bval[size + 4 :]
                b.truncate(len(leftovers))
                b.seek(0)
                b.write(leftovers)
                return decode_ros_handshake_header(bval)


def encode_ros_handshake_header(header: dict[Any, Any]) -> bytes:
    """``header`` encoded with its length prefix, fields sorted by name as ROS 1 writes them."""
    as_bytes = {
        (k.encode() if isinstance(k, str) else k): (v.encode() if isinstance(v, str) else v)
        for k, v in header.items()
    }
    return _headers.encode_header(
        {k.decode("utf-8", "surrogateescape"): v for k, v in sorted(as_bytes.items())}
    )


def write_ros_handshake_header(sock: socket.socket, header: dict[Any, Any]) -> int:
    """Send ``header`` on ``sock``; returns the bytes written."""
    s = encode_ros_handshake_header(header)
    sock.sendall(s)
    return len(s)
