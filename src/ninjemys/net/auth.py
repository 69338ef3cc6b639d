"""Opt-in authentication: one shared secret signs every XML-RPC request and TCPROS connection header.

ROS 1 authenticates nothing: anyone who reaches the master can register, publish, set parameters or
``rosnode kill`` a node. With ``NINJEMYS_SECRET`` set (or ``NINJEMYS_SECRET_FILE`` naming a file that
holds it), every ninjemys process signs what it sends and refuses what is not signed with the same
secret:

- XML-RPC (the master's API and every node's slave API): an HTTP header
  ``X-Ninjemys-Auth: v1 <time> <nonce> <mac>``, the MAC an HMAC-SHA256 over the time, the nonce and
  the request body. The body stays exactly ROS 1's.
- TCPROS and service connections (both directions): a connection-header field ``ninjemys_auth`` of
  the same form, over every other field of the header.

A signature is good for two minutes of clock difference and once only (nonces are remembered for that
window), so a recorded request cannot be replayed. Unset (the default), nothing is added or checked:
the wire is ROS 1's byte for byte. A ROS 1 node cannot sign, so with a secret set it is refused with a
message saying why (docs/auth.md: mixed graphs).
"""

from __future__ import annotations

import os
import threading
import time
from collections import OrderedDict
from collections.abc import Mapping

from ninjemys.errors import NinjemysError

TYPE_CHECKING = False  # importing typing costs ~7 ms of every node's start-up; checkers set it
if TYPE_CHECKING:
    from typing import Any

    from _typeshed import SizedBuffer

ENV_SECRET = "NINJEMYS_SECRET"
ENV_SECRET_FILE = "NINJEMYS_SECRET_FILE"
HTTP_HEADER = "X-Ninjemys-Auth"
TCPROS_FIELD = "ninjemys_auth"
#: seconds a signature stays good (clock difference between machines plus transit)
WINDOW = 120.0
_MAX_NONCES = 200_000


class AuthError(NinjemysError):
    """The secret cannot be read (a NINJEMYS_SECRET_FILE that is missing or empty)."""


def load_secret(env: Mapping[str, str] | None = None) -> bytes | None:
    """The shared secret, or None when authentication is off."""
    env = os.environ if env is None else env
    value = env.get(ENV_SECRET, "")
    if value:
        return value.encode("utf-8")
    path = env.get(ENV_SECRET_FILE, "")
    if not path:
        return None
    try:
        with open(path, "rb") as f:
            data = f.read().strip()
    except OSError as exc:
        raise AuthError(f"{ENV_SECRET_FILE}={path}: cannot read the secret: {exc.strerror or exc}") from None
    if not data:
        raise AuthError(f"{ENV_SECRET_FILE}={path}: the file is empty")
    return data


class Signer:
    """Signs and checks payloads with one secret; remembers the nonces it accepted (thread-safe)."""

    def __init__(self, key: bytes) -> None:
        # imported here: only a process with a secret pays for them (node start-up stays lean)
        import hashlib
        import hmac
        import itertools

        self._compare = hmac.compare_digest
        # keyed once, copied per message: with OpenSSL 3, hmac.digest(key, msg, "sha256") looks the
        # digest up on every call and costs ~4x a copy of a keyed HMAC (18 vs ~4 µs for a 340-byte call)
        self._keyed = hmac.new(key, digestmod=hashlib.sha256)
        # nonces need only be unique: a random prefix per signer and a counter (no syscall per call)
        self._prefix = os.urandom(6).hex()
        self._count = itertools.count()
        self._seen: OrderedDict[str, float] = OrderedDict()
        self._lock = threading.Lock()

    def _mac(self, stamp: str, nonce: str, payload: bytes) -> str:
        mac = self._keyed.copy()
        mac.update(stamp.encode() + b"\n" + nonce.encode() + b"\n")
        mac.update(payload)
        return mac.hexdigest()

    def sign(self, payload: bytes) -> str:
        stamp, nonce = f"{time.time():.3f}", f"{self._prefix}{next(self._count):x}"
        return f"v1 {stamp} {nonce} {self._mac(stamp, nonce, payload)}"

    def check(self, token: str | None, payload: bytes) -> str | None:
        """Why ``token`` does not authenticate ``payload`` (None: it does)."""
        if not token:
            return "not signed (this graph requires NINJEMYS_SECRET; ROS 1 nodes cannot join it)"
        parts = token.split(" ")
        if len(parts) != 4 or parts[0] != "v1":
            return "malformed signature"
        _, stamp, nonce, mac = parts
        try:
            when = float(stamp)
        except ValueError:
            return "malformed signature"
        now = time.time()
        if abs(now - when) > WINDOW:
            return f"signature from {now - when:+.0f} s away (clocks more than {WINDOW:.0f} s apart, or a replay)"
        if not self._compare(mac, self._mac(stamp, nonce, payload)):
            return "wrong secret"
        with self._lock:
            if nonce in self._seen:
                return "replayed signature"
            self._seen[nonce] = when
            while self._seen and (
                len(self._seen) > _MAX_NONCES or next(iter(self._seen.values())) < now - WINDOW
            ):
                self._seen.popitem(last=False)
        return None


_cache: tuple[bytes | None, Signer | None] = (None, None)


def signer() -> Signer | None:
    """The process's signer for the current secret, or None when authentication is off."""
    global _cache
    key = load_secret()
    if key is None:
        return None
    cached_key, cached = _cache
    if cached is None or cached_key != key:
        cached = Signer(key)
        _cache = (key, cached)
    return cached


# -- XML-RPC ---------------------------------------------------------------------------------------


def http_header_line(body: bytes) -> str:
    """The signature header line for an XML-RPC request body ("" when authentication is off)."""
    s = signer()
    return "" if s is None else f"{HTTP_HEADER}: {s.sign(body)}\r\n"


def check_http(headers: Mapping[str, str], body: bytes) -> str | None:
    """Why an XML-RPC request is refused (None: accepted, or authentication is off)."""
    s = signer()
    return None if s is None else s.check(headers.get(HTTP_HEADER.lower()), body)


# -- TCPROS connection headers ---------------------------------------------------------------------


def _canonical(fields: Mapping[str, str]) -> bytes:
    return "\n".join(f"{k}={fields[k]}" for k in sorted(fields) if k != TCPROS_FIELD).encode(
        "utf-8", "surrogateescape"
    )


def sign_fields(fields: dict[str, str]) -> dict[str, str]:
    """``fields`` with the signature field added (unchanged when authentication is off)."""
    s = signer()
    if s is not None:
        fields[TCPROS_FIELD] = s.sign(_canonical(fields))
    return fields


def check_fields(fields: Mapping[str, str]) -> str | None:
    """Why a connection header is refused (None: accepted, or authentication is off). An ``error``
    header from the peer is let through: it carries the peer's own refusal, to be reported."""
    s = signer()
    if s is None or ("error" in fields and len(fields) == 1):
        return None
    return s.check(fields.get(TCPROS_FIELD), _canonical(fields))


# -- the standard library's XML-RPC client (the ROS 1 facades' ServerProxy) ------------------------


def server_proxy(uri: str) -> Any:
    """``xmlrpc.client.ServerProxy(uri)`` that signs its requests when a secret is set."""
    import http.client
    import xmlrpc.client

    if signer() is None:
        return xmlrpc.client.ServerProxy(uri)

    class SignedTransport(xmlrpc.client.Transport):
        _body = b""

        def send_request(
            self, host: Any, handler: str, request_body: SizedBuffer, debug: bool
        ) -> http.client.HTTPConnection:
            self._body = bytes(request_body)
            return super().send_request(host, handler, request_body, debug)

        def send_headers(
            self, connection: http.client.HTTPConnection, headers: list[tuple[str, str]]
        ) -> None:
            s = signer()
            extra = [(HTTP_HEADER, s.sign(self._body))] if s is not None else []
            super().send_headers(connection, [*headers, *extra])

    return xmlrpc.client.ServerProxy(uri, transport=SignedTransport())
