"""Opt-in authentication: a shared secret, or per-node keys, sign every XML-RPC request and TCPROS header.

ROS 1 authenticates nothing: anyone who reaches the master can register, publish, set parameters or
``rosnode kill`` a node. Two opt-in modes close that (docs/auth.md):

- a shared secret, ``NINJEMYS_SECRET`` (or ``NINJEMYS_SECRET_FILE`` naming a file that holds it):
  every ninjemys process of the graph signs with it and checks with it;
- per-node keys, ``NINJEMYS_KEYS_FILE`` naming a file of ``<name> <key>`` lines (a name, or a pattern
  ending in ``*`` that covers every name starting with what precedes it): a request is checked with
  the key of the caller it *claims to be* (the XML-RPC ``caller_id``, the TCPROS ``callerid``), so a
  key only lets its holder speak as the names it is listed for. A process signs with ``NINJEMYS_KEY``
  when set, else with the file's key for the name it speaks as.

What is signed:

- XML-RPC (the master's API and every node's slave API): an HTTP header
  ``X-Ninjemys-Auth: v2 <time> <nonce> <mac>``, the MAC an HMAC-SHA256 (first 128 bits) over
  what precedes it and the request body. The body stays exactly ROS 1's.
- TCPROS and service connections (both directions): a connection-header field ``ninjemys_auth`` of
  the same form, over every other field of the header.

A signature is good for two minutes of clock difference and once only (nonces are remembered for that
window), so a recorded request cannot be replayed. Unset (the default), nothing is added or checked:
the wire is ROS 1's byte for byte. A ROS 1 node cannot sign, so with authentication on it is refused
with a message saying why (docs/auth.md: mixed graphs).

Cost matters: the master's cheapest calls take ~150 us of CPU on both sides together, and the target
is at most 10 % more with authentication on. So the HMAC is computed from two pre-keyed SHA-256
states (two C-level copies instead of ``hmac``'s Python-level ones), the nonce is a per-process random
prefix plus a counter (no syscall), and the hot paths (the master client, the XML-RPC server) look the
credentials up once when they are built instead of reading the environment on every call.
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
ENV_KEYS_FILE = "NINJEMYS_KEYS_FILE"
ENV_KEY = "NINJEMYS_KEY"
_ENV_ALL = (ENV_SECRET, ENV_SECRET_FILE, ENV_KEYS_FILE, ENV_KEY)
HTTP_HEADER = "X-Ninjemys-Auth"
#: the signature's format: v1 (before 2026-11-29) carried the whole 256-bit MAC over another layout
VERSION = "v2"
TCPROS_FIELD = "ninjemys_auth"
#: seconds a signature stays good (clock difference between machines plus transit)
WINDOW = 120.0
_MAX_NONCES = 200_000
#: how every refusal starts, in XML-RPC statuses and TCPROS error headers
REFUSAL = "authentication failed"
_NOT_SIGNED = "not signed (this graph requires authentication; ROS 1 nodes cannot join it)"


class AuthError(NinjemysError):
    """The credentials cannot be read (a missing or empty secret file, a malformed keys file)."""


def load_secret(env: Mapping[str, str] | None = None) -> bytes | None:
    """The shared secret, or None when none is set (authentication off, or per-node keys)."""
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
    """Signs and checks payloads with one key; remembers the nonces it accepted (thread-safe)."""

    def __init__(self, key: bytes) -> None:
        # imported here: only a process with a secret pays for it (node start-up stays lean)
        import hashlib
        import hmac
        import itertools

        self.key = key  # as given: the gateway and the Zenoh bridge derive their credentials from it
        # HMAC (RFC 2104) from two SHA-256 states keyed once: a message costs two C-level copies;
        # hmac.HMAC.copy() is Python code and doubled the cost of signing a 300-byte call
        if len(key) > 64:
            key = hashlib.sha256(key).digest()
        key = key.ljust(64, b"\0")
        self._inner = hashlib.sha256(bytes(b ^ 0x36 for b in key))
        self._outer = hashlib.sha256(bytes(b ^ 0x5C for b in key))
        self._compare = hmac.compare_digest
        # nonces need only be unique: a random prefix per signer and a counter (no syscall per call)
        self._prefix = os.urandom(6).hex()
        self._count = itertools.count()
        self._seen: OrderedDict[str, float] = OrderedDict()
        self._lock = threading.Lock()

    def mac(self, head: str, payload: bytes) -> str:
        """The first 128 bits (hex) of HMAC-SHA256(key, head + payload)."""
        inner = self._inner.copy()
        inner.update(head.encode())
        inner.update(payload)
        outer = self._outer.copy()
        outer.update(inner.digest())
        return outer.hexdigest()[:32]

    def sign(self, payload: bytes) -> str:
        """``v2 <time> <nonce> <mac>``, the MAC over everything before it and the payload."""
        head = f"{VERSION} {time.time():.3f} {self._prefix}{next(self._count):x} "
        return head + self.mac(head, payload)

    def check(self, token: str | None, payload: bytes) -> str | None:
        """Why ``token`` does not authenticate ``payload`` (None: it does)."""
        if not token:
            return _NOT_SIGNED
        parts = token.split(" ")
        if len(parts) != 4 or parts[0] != VERSION:
            return "malformed signature"
        _, stamp, nonce, mac = parts
        try:
            when = float(stamp)
        except ValueError:
            return "malformed signature"
        now = time.time()
        if abs(now - when) > WINDOW:
            return f"signature from {now - when:+.0f} s away (clocks more than {WINDOW:.0f} s apart, or a replay)"
        if not self._compare(mac, self.mac(token[: -len(mac)], payload)):
            return "wrong secret"
        with self._lock:
            seen = self._seen
            if nonce in seen:
                return "replayed signature"
            seen[nonce] = when
            if len(seen) > _MAX_NONCES or next(iter(seen.values())) < now - WINDOW:
                while seen and (len(seen) > _MAX_NONCES or next(iter(seen.values())) < now - WINDOW):
                    seen.popitem(last=False)
        return None


# -- per-node keys ---------------------------------------------------------------------------------


def parse_keys(text: str, source: str = "<keys>") -> dict[str, bytes]:
    """``<name> <key>`` lines -> {name or pattern: key}. A name is a global graph name (``/talker``),
    or a pattern ending in ``*`` covering every name that starts with what precedes the star
    (``/robot1/*``, ``/rostopic_*``, ``*`` for every name). A key is one word (it may hold ``#``);
    blank lines, lines starting with ``#`` and ``# ...`` after the key are comments."""
    keys: dict[str, bytes] = {}
    for number, raw in enumerate(text.splitlines(), 1):
        parts = raw.split()
        if not parts or parts[0].startswith("#"):
            continue
        where = f"{source}:{number}"
        if len(parts) < 2 or (len(parts) > 2 and not parts[2].startswith("#")):
            raise AuthError(f"{where}: expected '<node name> <key>', got {raw.strip()[:60]!r}")
        name, key = parts[0], parts[1]
        if not (name.startswith("/") or name == "*") or "*" in name[:-1]:
            raise AuthError(
                f"{where}: {name!r} is not a global node name (/talker) or a pattern ending in * (/robot1/*)"
            )
        if name in keys:
            raise AuthError(f"{where}: {name} is listed twice")
        keys[name] = key.encode("utf-8")
    if not keys:
        raise AuthError(f"{source}: no keys")
    return keys


def load_keys(path: str) -> dict[str, bytes]:
    """The keys file at ``path`` (see :func:`parse_keys`)."""
    try:
        with open(path, encoding="utf-8") as f:
            text = f.read()
    except (OSError, UnicodeDecodeError) as exc:
        why = exc.strerror if isinstance(exc, OSError) and exc.strerror else exc
        raise AuthError(f"{ENV_KEYS_FILE}={path}: cannot read the keys: {why}") from None
    return parse_keys(text, path)


class Credentials:
    """What one process signs with and checks callers against.

    Shared-secret mode is the special case of one key for every name (``single``): the caller's name
    is then never needed, and the hot paths skip finding it.
    """

    def __init__(self, keys: Mapping[str, bytes], own: bytes | None = None, source: str = "") -> None:
        self.source = source
        self._exact = {name: Signer(key) for name, key in keys.items() if not name.endswith("*")}
        # longest pattern first: /robot1/arm/* wins over /robot1/*
        self._patterns = sorted(
            ((name[:-1], Signer(key)) for name, key in keys.items() if name.endswith("*")),
            key=lambda item: -len(item[0]),
        )
        self._own = Signer(own) if own is not None else None
        self.single: Signer | None = None
        if not self._exact and len(self._patterns) == 1 and self._patterns[0][0] == "" and own is None:
            self.single = self._own = self._patterns[0][1]

    @property
    def can_check(self) -> bool:
        """False for a process that holds only its own key (NINJEMYS_KEY without a keys file)."""
        return bool(self._exact or self._patterns)

    def key_for(self, name: str) -> Signer | None:
        """The signer for a caller claiming ``name`` (None: no key covers it)."""
        found = self._exact.get(name)
        if found is not None:
            return found
        for prefix, signer in self._patterns:
            if name.startswith(prefix):
                return signer
        return None

    def listed_names(self) -> list[tuple[str, bytes]]:
        """(name, key) of every name listed exactly (not patterns)."""
        return [(name, s.key) for name, s in self._exact.items()]

    def signer_for(self, name: str) -> Signer | None:
        """The signer this process uses when it speaks as ``name``."""
        return self._own if self._own is not None else self.key_for(name)

    def sign(self, payload: bytes, caller: str) -> str | None:
        s = self.single or self.signer_for(caller)
        return None if s is None else s.sign(payload)

    def check(self, token: str | None, payload: bytes, caller: str) -> str | None:
        """Why a request from a caller claiming ``caller`` is refused (None: accepted)."""
        s = self.single
        if s is None:
            if not self.can_check:
                return f"this process cannot check callers: it has {ENV_KEY} but no {ENV_KEYS_FILE}"
            if not token:
                return f"not signed (this graph requires per-node keys: {caller or 'the caller'} has none, or is a ROS 1 node)"
            s = self.key_for(caller)
            if s is None:
                return f"no key for {caller or 'a caller without a name'} in {self.source}"
        return s.check(token, payload)

    def secret_for(self, name: str) -> bytes | None:
        """The key ``name`` signs with: what the gateway and the Zenoh bridge derive theirs from."""
        s = self.single or self.signer_for(name)
        return None if s is None else s.key


def load_credentials(env: Mapping[str, str] | None = None) -> Credentials | None:
    """The process's credentials from the environment, or None when authentication is off."""
    env = os.environ if env is None else env
    secret = load_secret(env)
    keys_file, own = env.get(ENV_KEYS_FILE, ""), env.get(ENV_KEY, "")
    if secret is not None:
        if keys_file or own:
            raise AuthError(
                f"both a shared secret ({ENV_SECRET}/{ENV_SECRET_FILE}) and per-node keys "
                f"({ENV_KEYS_FILE}/{ENV_KEY}) are set: use one (a keys file line '* <secret>' gives "
                "every name not listed the shared secret)"
            )
        return Credentials({"*": secret}, source=ENV_SECRET)
    if not keys_file and not own:
        return None
    keys = load_keys(keys_file) if keys_file else {}
    return Credentials(keys, own.encode("utf-8") if own else None, source=keys_file or ENV_KEY)


_cache: tuple[tuple[str, ...], Credentials | None] = ((), None)


def credentials() -> Credentials | None:
    """The process's credentials for the current environment (cached), or None when authentication is off."""
    global _cache
    env = os.environ
    state = tuple(env.get(name, "") for name in _ENV_ALL)
    cached_state, cached = _cache
    if state != cached_state:
        cached = load_credentials() if any(state) else None
        _cache = (state, cached)
    return cached


def signer() -> Signer | None:
    """The shared-secret signer, or None when authentication is off or uses per-node keys."""
    creds = credentials()
    return None if creds is None else creds.single


# -- XML-RPC ---------------------------------------------------------------------------------------


def xmlrpc_caller(body: bytes) -> str:
    """The first parameter of an XML-RPC call (the caller_id of every ROS API), "" when there is none.
    Only per-node keys need it; read straight from the bytes, without parsing the whole call."""
    start = body.find(b"<param>")
    if start < 0:
        return ""
    start = body.find(b"<value>", start)
    end = body.find(b"</value>", start)
    if start < 0 or end < 0:
        return ""
    text = body[start + 7 : end].strip()
    if text.startswith(b"<string>"):
        text = text[8:]
    if text.endswith(b"</string>"):
        text = text[:-9]
    elif text.startswith(b"<"):
        return ""  # not a string
    name = text.decode("utf-8", "replace")
    if "&" in name:
        name = name.replace("&lt;", "<").replace("&gt;", ">").replace("&amp;", "&")
    return name


def header_line(creds: Credentials | None, body: bytes, caller: str | None = None) -> str:
    """The signature header line for an XML-RPC request body ("" when authentication is off, or when
    no key covers the caller: the receiver then says the request is not signed)."""
    if creds is None:
        return ""
    s = creds.single
    if s is None:
        s = creds.signer_for(xmlrpc_caller(body) if caller is None else caller)
        if s is None:
            return ""
    return f"{HTTP_HEADER}: {s.sign(body)}\r\n"


def http_header_line(body: bytes, caller: str | None = None) -> str:
    """:func:`header_line` with the process's current credentials."""
    return header_line(credentials(), body, caller)


def check_request(
    creds: Credentials | None, headers: Mapping[str, str], body: bytes, params: Any = ()
) -> str | None:
    """Why an XML-RPC request is refused (None: accepted, or authentication is off). ``params``: the
    parsed call's parameters when the server has them (the caller is the first)."""
    if creds is None:
        return None
    token = headers.get("x-ninjemys-auth")
    if creds.single is not None:
        return creds.single.check(token, body)
    caller = params[0] if params and isinstance(params[0], str) else xmlrpc_caller(body)
    return creds.check(token, body, caller)


ANY_CALLER = "*"


def check_on_connection(
    creds: Credentials | None, trusted: str | None, headers: Mapping[str, str], body: bytes, params: Any
) -> tuple[str | None, str | None]:
    """(why the request is refused or None, whom the connection is trusted for from now on).

    A keep-alive connection is authenticated once, like a TCPROS connection: its first signed request
    that checks makes the connection trusted for that caller (for every caller with a shared secret),
    and later requests on it for that caller need no signature. Signing and checking every call
    cost ~20 us of CPU on a ~150 us master call on a busy machine (cold caches), twice the 10 % the
    feature may cost; a connection carries no more trust than a TCPROS connection does.
    """
    if creds is None:
        return None, trusted
    if trusted is not None and "x-ninjemys-auth" not in headers:
        if trusted == ANY_CALLER:
            return None, trusted
        caller = params[0] if params and isinstance(params[0], str) else ""
        if caller == trusted:
            return None, trusted
    refused = check_request(creds, headers, body, params)
    if refused is not None:
        return refused, trusted
    if creds.single is not None:
        return None, ANY_CALLER
    return None, params[0] if params and isinstance(params[0], str) else xmlrpc_caller(body)


def is_refusal(result: Any) -> bool:
    """Whether an XML-RPC result is an authentication refusal (``[-1, "authentication failed: ...", 0]``)."""
    return (
        isinstance(result, list)
        and len(result) == 3
        and result[0] == -1
        and isinstance(result[1], str)
        and result[1].startswith(REFUSAL)
    )


def check_http(headers: Mapping[str, str], body: bytes) -> str | None:
    """:func:`check_request` with the process's current credentials."""
    return check_request(credentials(), headers, body)


# -- TCPROS connection headers ---------------------------------------------------------------------


def _canonical(fields: Mapping[str, str]) -> bytes:
    return "\n".join(f"{k}={fields[k]}" for k in sorted(fields) if k != TCPROS_FIELD).encode(
        "utf-8", "surrogateescape"
    )


def sign_fields(fields: dict[str, str]) -> dict[str, str]:
    """``fields`` with the signature field added (unchanged when authentication is off). Per-node keys:
    signed with the key of the ``callerid`` field."""
    creds = credentials()
    if creds is not None:
        token = creds.sign(_canonical(fields), fields.get("callerid", ""))
        if token is not None:
            fields[TCPROS_FIELD] = token
    return fields


def check_fields(fields: Mapping[str, str]) -> str | None:
    """Why a connection header is refused (None: accepted, or authentication is off). An ``error``
    header from the peer is let through: it carries the peer's own refusal, to be reported."""
    creds = credentials()
    if creds is None or ("error" in fields and len(fields) == 1):
        return None
    return creds.check(fields.get(TCPROS_FIELD), _canonical(fields), fields.get("callerid", ""))


# -- the standard library's XML-RPC client (the ROS 1 facades' ServerProxy) ------------------------


def server_proxy(uri: str) -> Any:
    """``xmlrpc.client.ServerProxy(uri)`` that signs its requests when authentication is on."""
    import http.client
    import xmlrpc.client

    if credentials() is None:
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
            line = http_header_line(self._body)
            extra = [(HTTP_HEADER, line.split(": ", 1)[1].strip())] if line else []
            super().send_headers(connection, [*headers, *extra])

    return xmlrpc.client.ServerProxy(uri, transport=SignedTransport())
