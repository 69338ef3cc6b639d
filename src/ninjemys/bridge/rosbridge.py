"""rosbridge v2 protocol (RobotWebTools' ROSBRIDGE_PROTOCOL.md, ROS 1 flavour) for one client.

Incoming ops are handled in order on the session's own worker thread (they may block on the
master or on a peer), except ``call_service``, which runs on the gateway's pool so a slow service
never holds up the client's other ops. Outgoing data goes through the client's :class:`Outbox`.

Errors in a client's message become a ``status`` op (level ``error``, the message's ``id``) naming
the op, the field and what was wrong; the connection stays open.
"""

from __future__ import annotations

import base64
import hashlib
import hmac
import itertools
import json
import logging
import math
import struct
import threading
import time
import zlib
from collections.abc import Callable
from concurrent.futures import Executor, ThreadPoolExecutor
from typing import Any

import cbor2

from ninjemys.bridge.convert import ConversionError, from_value, to_value
from ninjemys.bridge.graph import Delivery
from ninjemys.bridge.graph import service_class as graph_service_class
from ninjemys.bridge.outbox import Backlog, Outbox
from ninjemys.errors import NinjemysError

log = logging.getLogger(__name__)

_LEVELS = {"none": 0, "error": 1, "warning": 2, "info": 3}
#: lane length when a subscription asks for queue_length 0 (rosbridge's "no queue" default)
DEFAULT_QUEUE_LENGTH = 100
#: fragmented messages a client may have unfinished at once (each is bounded by max_message_size)
MAX_PENDING_FRAGMENTED = 8


class OpError(NinjemysError):
    """A client message the session refuses; the text goes back in a ``status`` op."""


def png_compress(text: str) -> str:
    """rosbridge's ``png`` compression: the UTF-8 bytes as an RGB image, padded with newlines to a
    near-square width x height x 3, saved as PNG and base64-encoded (what roslibjs decodes)."""
    data = text.encode("utf-8")
    width = max(1, math.floor(math.sqrt(len(data) / 3.0)))
    height = max(1, math.ceil((len(data) / 3.0) / width))
    data += b"\n" * (width * height * 3 - len(data))
    stride = width * 3
    raw = b"".join(b"\x00" + data[row * stride : (row + 1) * stride] for row in range(height))

    def chunk(kind: bytes, body: bytes) -> bytes:
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))

    png = (
        b"\x89PNG\r\n\x1a\n"
        + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
        + chunk(b"IDAT", zlib.compress(raw, 6))
        + chunk(b"IEND", b"")
    )
    return base64.b64encode(png).decode("ascii")


def rosauth_mac(
    secret: str, client: str, dest: str, rand: str, t_secs: int, level: str, end_secs: int
) -> str:
    """rosauth's MAC: hex SHA-512 of secret + client + dest + rand + t.sec + level + end.sec."""
    text = f"{secret}{client}{dest}{rand}{t_secs}{level}{end_secs}"
    return hashlib.sha512(text.encode("utf-8")).hexdigest()


def _secs(value: Any) -> int:
    if isinstance(value, dict):
        return int(value.get("secs", 0))
    if isinstance(value, int | float) and not isinstance(value, bool):
        return int(value)
    raise OpError(f"expected a time (seconds or {{secs, nsecs}}), got {value!r}")


class _Subscription:
    """One client's subscription to a topic (rosbridge merges repeated subscribes by id)."""

    __slots__ = ("topic", "type", "ids", "last_sent")

    def __init__(self, topic: str, type_name: str) -> None:
        self.topic = topic
        self.type = type_name
        self.ids: dict[str | None, dict[str, Any]] = {}
        self.last_sent = 0.0

    def options(self) -> dict[str, Any]:
        opts = list(self.ids.values())
        return {
            "throttle_rate": min(o["throttle_rate"] for o in opts),
            "queue_length": max(o["queue_length"] for o in opts),
            "fragment_size": min((o["fragment_size"] for o in opts if o["fragment_size"]), default=None),
            "compression": opts[-1]["compression"],
        }


class RosbridgeSession:
    """The rosbridge v2 protocol for one connected client."""

    def __init__(self, gateway: Any, client_id: int, outbox: Outbox) -> None:
        self.gateway = gateway
        self.client_id = client_id
        self.outbox = outbox
        self.authenticated = not gateway.options.authenticate
        self.status_level = _LEVELS["error"]
        self._subs: dict[str, _Subscription] = {}
        self._advertised: set[str] = set()
        self._services: dict[str, Any] = {}
        self._pending: dict[str, tuple[threading.Event, list[Any]]] = {}
        self._fragments: dict[str, dict[int, str]] = {}
        self._counter = itertools.count(1)
        self.backlog = Backlog()
        self._worker: Executor = ThreadPoolExecutor(1, thread_name_prefix=f"rosbridge-{client_id}")
        self._closed = threading.Event()
        self._lock = threading.Lock()
        #: per lane thread: the running call's claim on its reply (see :meth:`_dispatch_call`)
        self._call = threading.local()

    # -- sending ------------------------------------------------------------------------------
    def send(self, obj: dict[str, Any]) -> None:
        """Replies and statuses (JSON, as rosbridge answers whatever the client sent)."""
        self.outbox.put_control(json.dumps(obj))

    def status(self, level: str, msg: str, op_id: Any = None) -> None:
        if _LEVELS[level] > self.status_level:
            return
        out: dict[str, Any] = {"op": "status", "level": level, "msg": msg}
        if op_id is not None:
            out["id"] = op_id
        self.send(out)

    # -- receiving ----------------------------------------------------------------------------
    def receive(self, data: str | bytes) -> None:
        """One WebSocket message from the client (called on the event loop; never blocks)."""
        if self._closed.is_set():
            return
        try:
            if isinstance(data, str):
                msg = json.loads(data)
            else:
                msg = cbor2.loads(data)
        except (ValueError, EOFError) as exc:
            self.status("error", f"malformed message ({'JSON' if isinstance(data, str) else 'CBOR'}): {exc}")
            return
        if not isinstance(msg, dict) or not isinstance(msg.get("op"), str):
            self.status("error", "a rosbridge message must be an object with an 'op' string")
            return
        self.backlog.add()
        if msg["op"] == "call_service" and self.authenticated:
            self._dispatch_call(msg)
        else:
            self._worker.submit(self._run, msg)

    def _dispatch_call(self, msg: dict[str, Any]) -> None:
        """A call runs on its service's lane with a bounded wait: the ``timeout`` field (seconds, as
        in rosbridge's newer protocol) or the gateway's ``call_services_timeout``."""
        timeout = msg.get("timeout")
        if not isinstance(timeout, (int, float)) or isinstance(timeout, bool) or timeout <= 0:
            timeout = self.gateway.options.call_service_timeout
        service = str(msg.get("service"))

        def work(claim: Callable[[], bool]) -> None:
            won: list[bool] = []

            def first() -> bool:
                if not won:
                    won.append(claim())
                return won[0]

            self._call.claim = first
            try:
                self._handle(msg)
            finally:
                self._call.claim = None
                if first():  # this call answered (or errored before the deadline): free its slot
                    self.backlog.done()

        def expired() -> None:
            reply: dict[str, Any] = {"op": "service_response", "service": service, "result": False}
            reply["values"] = f"service {service} did not answer within {timeout:g} s"
            if msg.get("id") is not None:
                reply["id"] = msg["id"]
            self.send(reply)
            self.backlog.done()

        try:
            self.gateway.services.dispatch(service, timeout, work, expired)
        except NinjemysError as exc:
            self.status("error", f"call_service: {exc}", msg.get("id"))
            self.backlog.done()

    def _run(self, msg: dict[str, Any]) -> None:
        try:
            self._handle(msg)
        finally:
            self.backlog.done()

    def _handle(self, msg: dict[str, Any]) -> None:
        op = msg["op"]
        op_id = msg.get("id")
        if not self.authenticated and op != "auth":
            # rosbridge refuses everything before a successful auth, and says so once per message
            self.status("error", f"{op}: the client is not authenticated (send an 'auth' op first)", op_id)
            return
        handler = getattr(self, "op_" + op, None)
        if handler is None:
            self.status("error", f"unknown op {op!r}", op_id)
            return
        try:
            handler(msg)
        except (OpError, ConversionError, NinjemysError) as exc:
            self.status("error", f"{op}: {exc}", op_id)
        except (KeyError, TypeError, ValueError) as exc:
            self.status("error", f"{op}: bad message: {type(exc).__name__}: {exc}", op_id)
        except Exception as exc:  # a gateway bug stays one client's error, not the server's
            log.exception("rosbridge: op %s failed", op)
            self.status("error", f"{op}: {type(exc).__name__}: {exc}", op_id)

    @staticmethod
    def _field(msg: dict[str, Any], name: str, kind: type | tuple[type, ...], default: Any = ...) -> Any:
        value = msg.get(name, default)
        if value is ...:
            raise OpError(f"missing field {name!r}")
        if value is not default and (
            not isinstance(value, kind) or isinstance(value, bool) and kind is not bool
        ):
            names = kind.__name__ if isinstance(kind, type) else "/".join(k.__name__ for k in kind)
            raise OpError(f"field {name!r} must be {names}, got {type(value).__name__}")
        return value

    def _topic(self, msg: dict[str, Any], field: str = "topic") -> str:
        name = self._field(msg, field, str)
        try:
            return self.gateway.node.resolve_name(name)
        except NinjemysError as exc:
            raise OpError(str(exc)) from None

    # -- ops ----------------------------------------------------------------------------------
    def op_auth(self, msg: dict[str, Any]) -> None:
        secret = self.gateway.options.secret()
        if secret is None:
            self.authenticated = True  # authentication off: rosbridge ignores auth ops
            return
        try:
            mac = self._field(msg, "mac", str)
            client = self._field(msg, "client", str)
            dest = self._field(msg, "dest", str)
            rand = self._field(msg, "rand", str)
            level = self._field(msg, "level", str)
            t, end = _secs(msg.get("t")), _secs(msg.get("end"))
        except OpError as exc:
            self._refuse(f"auth: {exc}")
            return
        now = time.time()
        expected = rosauth_mac(secret, client, dest, rand, t, level, end)
        if abs(now - t) > self.gateway.options.auth_time_delta or end < now:
            self._refuse("auth: the MAC's time window is not current")
        elif not hmac.compare_digest(expected, mac):
            self._refuse("auth: wrong MAC")
        else:
            self.authenticated = True
            log.info("rosbridge: client %d authenticated as %s", self.client_id, client)

    def _refuse(self, why: str) -> None:
        self.status("error", why)
        self.gateway.close_client(self.client_id, 4001, "authentication failed")

    def op_set_level(self, msg: dict[str, Any]) -> None:
        level = self._field(msg, "level", str)
        if level not in _LEVELS:
            raise OpError(f"level must be one of {', '.join(_LEVELS)}, got {level!r}")
        self.status_level = _LEVELS[level]

    def op_status(self, msg: dict[str, Any]) -> None:
        """A client asking for the session's state gets its subscriptions and drop counts."""
        dropped = dict(self.outbox.dropped)
        self.send(
            {
                "op": "status",
                "level": "info",
                "msg": json.dumps({"subscriptions": sorted(self._subs), "dropped": dropped}),
                **({"id": msg["id"]} if "id" in msg else {}),
            }
        )

    def op_advertise(self, msg: dict[str, Any]) -> None:
        topic = self._topic(msg)
        type_name = self._field(msg, "type", str)
        latch = self._field(msg, "latch", bool, False)
        queue_size = self._field(msg, "queue_size", int, 100)
        self.gateway.publishers.advertise(topic, type_name, self, latch=latch, queue_size=queue_size)
        self._advertised.add(topic)

    def op_unadvertise(self, msg: dict[str, Any]) -> None:
        topic = self._topic(msg)
        if topic in self._advertised:
            self._advertised.discard(topic)
            self.gateway.publishers.unadvertise(topic, self)

    def op_publish(self, msg: dict[str, Any]) -> None:
        topic = self._topic(msg)
        if topic not in self._advertised:
            # rosbridge advertises implicitly on publish, with the topic's known type
            type_name = self.gateway.topic_type(topic)
            if type_name is None:
                raise OpError(f"cannot infer the type of {topic}: advertise it first")
            self.gateway.publishers.advertise(topic, type_name, self)
            self._advertised.add(topic)
        pub, msg_class = self.gateway.publishers.get(topic)
        body = msg.get("msg", {})
        pub.publish(from_value(msg_class, body, f"{topic} ({msg_class._type})"))

    def op_subscribe(self, msg: dict[str, Any]) -> None:
        topic = self._topic(msg)
        type_name = self._field(msg, "type", str, None)
        opts = {
            "throttle_rate": self._field(msg, "throttle_rate", int, 0),
            "queue_length": self._field(msg, "queue_length", int, 0),
            "fragment_size": self._field(msg, "fragment_size", int, None),
            "compression": self._field(msg, "compression", str, "none"),
        }
        for name in ("throttle_rate", "queue_length", "fragment_size"):
            if opts[name] is not None and opts[name] < 0:
                raise OpError(f"field {name!r} must not be negative, got {opts[name]}")
        if opts["fragment_size"] == 0:
            opts["fragment_size"] = None
        if opts["compression"] not in ("none", "png", "cbor", "cbor-raw"):
            raise OpError(f"compression must be none, png, cbor or cbor-raw, got {opts['compression']!r}")
        with self._lock:
            sub = self._subs.get(topic)
        if sub is None:
            if not type_name:
                type_name = self.gateway.topic_type(topic)
                if type_name is None:
                    raise OpError(f"cannot infer the type of {topic}: give 'type' or wait for a publisher")
            sub = _Subscription(topic, type_name)
            sub.ids[msg.get("id")] = opts
            # recorded only once the tap accepted it: a refused subscribe leaves nothing behind
            sub.type = self.gateway.taps.add(
                topic, type_name, self, self._sink(sub), published_as=self.gateway.topic_type(topic)
            )
            with self._lock:
                self._subs[topic] = sub
        else:
            sub.ids[msg.get("id")] = opts

    def op_unsubscribe(self, msg: dict[str, Any]) -> None:
        topic = self._topic(msg)
        with self._lock:
            sub = self._subs.get(topic)
            if sub is None:
                return
            sub.ids.pop(msg.get("id"), None)
            if "id" in msg and sub.ids:
                return
            del self._subs[topic]
        self.gateway.taps.remove(topic, self)
        self.outbox.discard(topic)

    def _sink(self, sub: _Subscription) -> Callable[[Delivery], None]:
        topic = sub.topic
        outbox = self.outbox

        def deliver(d: Delivery) -> None:
            opts = sub.options()
            if opts["throttle_rate"]:
                now = time.monotonic()
                if (now - sub.last_sent) * 1000.0 < opts["throttle_rate"]:
                    return
                sub.last_sent = now
            item = d.encoded((opts["compression"], opts["fragment_size"]), _encoder(opts))
            outbox.put(topic, item, opts["queue_length"] or DEFAULT_QUEUE_LENGTH)

        return deliver

    def op_call_service(self, msg: dict[str, Any]) -> None:
        service = self._topic(msg, "service")
        args = msg.get("args", {})
        op_id = msg.get("id")
        type_name = self._field(msg, "type", str, None)

        def build(request_class: Any) -> Any:
            if isinstance(args, list):  # rosbridge accepts the request's fields in order
                return from_value(
                    request_class, dict(zip(request_class.__slots__, args, strict=False)), service
                )
            return from_value(request_class, args, service)

        reply: dict[str, Any] = {"op": "service_response", "service": msg["service"]}
        if op_id is not None:
            reply["id"] = op_id
        try:
            response = self.gateway.services.call(service, type_name, build)
        except (ConversionError, OpError) as exc:
            reply.update(result=False, values=str(exc))
            self.status("error", f"call_service: {exc}", op_id)
        except NinjemysError as exc:
            reply.update(result=False, values=str(exc))
        else:
            reply.update(result=True, values=to_value(response))
        claim = getattr(self._call, "claim", None)
        if claim is None or claim():  # not past its deadline (then the client has its answer)
            self.send(reply)

    def op_advertise_service(self, msg: dict[str, Any]) -> None:
        service = self._topic(msg, "service")
        type_name = self._field(msg, "type", str)
        service_class = graph_service_class(type_name)
        with self._lock:
            old = self._services.pop(service, None)
        if old is not None:
            old.shutdown()

        def handler(request: Any) -> Any:
            call_id = f"service_request:{service}:{next(self._counter)}"
            done = threading.Event()
            slot: list[Any] = []
            with self._lock:
                if self._closed.is_set():
                    raise NinjemysError(f"service {service}: the providing WebSocket client went away")
                self._pending[call_id] = (done, slot)
            self.send({"op": "call_service", "id": call_id, "service": service, "args": to_value(request)})
            done.wait()  # set by the client's service_response, or by _abandon when it goes away
            values, result = slot
            if result is None:
                raise NinjemysError(f"service {service}: {values}")
            if not result:
                raise NinjemysError(
                    f"service {service}: the WebSocket client answered with an error: {values}"
                )
            return from_value(service_class._response_class, values, f"{service} response")

        server = self.gateway.node.service(service, service_class, handler)
        with self._lock:
            self._services[service] = server

    def op_unadvertise_service(self, msg: dict[str, Any]) -> None:
        service = self._topic(msg, "service")
        with self._lock:
            server = self._services.pop(service, None)
        if server is None:
            raise OpError(f"service {service} is not advertised by this client")
        self._abandon(f"service_request:{service}:", "the WebSocket client unadvertised it")
        server.shutdown()

    def _abandon(self, prefix: str, why: str) -> None:
        """Fail the ROS callers still waiting for this client's answers (ids starting with ``prefix``)."""
        with self._lock:
            ids = [i for i in self._pending if i.startswith(prefix)]
            abandoned = [self._pending.pop(i) for i in ids]
        for done, slot in abandoned:
            slot[:] = [why, None]
            done.set()

    def op_service_response(self, msg: dict[str, Any]) -> None:
        call_id = self._field(msg, "id", str)
        with self._lock:
            pending = self._pending.pop(call_id, None)
        if pending is None:
            raise OpError(f"no pending service request with id {call_id!r}")
        done, slot = pending
        slot[:] = [msg.get("values", {}), bool(msg.get("result", True))]
        done.set()

    def op_fragment(self, msg: dict[str, Any]) -> None:
        frag_id = str(self._field(msg, "id", (str, int)))
        num = self._field(msg, "num", int)
        total = self._field(msg, "total", int)
        data = self._field(msg, "data", str)
        if not 0 <= num < total or total > 100_000:
            raise OpError(f"fragment {num} of {total} is out of range")
        if frag_id not in self._fragments and len(self._fragments) >= MAX_PENDING_FRAGMENTED:
            oldest = next(iter(self._fragments))
            del self._fragments[oldest]
            self.status("warning", f"fragment: dropped the unfinished message {oldest} (too many pending)")
        parts = self._fragments.setdefault(frag_id, {})
        parts[num] = data
        if sum(len(p) for p in parts.values()) > self.gateway.options.max_message_size:
            del self._fragments[frag_id]
            raise OpError(f"fragmented message {frag_id} exceeds the message size limit")
        if len(parts) == total:
            del self._fragments[frag_id]
            text = "".join(parts[i] for i in range(total))
            self.receive(text)

    # -- end ----------------------------------------------------------------------------------
    def close(self) -> None:
        """The client went away: drop its subscriptions, publishers and services."""
        with self._lock:
            self._closed.set()
        self._abandon("", "the providing WebSocket client went away")

        def cleanup() -> None:
            for topic in list(self._subs):
                self.gateway.taps.remove(topic, self)
            self._subs.clear()
            for topic in list(self._advertised):
                self.gateway.publishers.unadvertise(topic, self)
            self._advertised.clear()
            for server in list(self._services.values()):
                server.shutdown(grace=1.0)  # the abandoned calls answer "went away" first
            self._services.clear()

        self._worker.submit(cleanup)
        self._worker.shutdown(wait=False)


def _encoder(opts: dict[str, Any]) -> Callable[[Delivery], Any]:
    compression = opts["compression"]
    fragment_size = opts["fragment_size"]

    def build(d: Delivery) -> Any:
        if compression == "cbor-raw":
            secs, nsecs = divmod(d.stamp_ns, 1_000_000_000)
            return cbor2.dumps(
                {
                    "op": "publish",
                    "topic": d.topic,
                    "msg": {"secs": secs, "nsecs": nsecs, "bytes": bytes(d.data)},
                }
            )
        if compression == "cbor":
            return cbor2.dumps({"op": "publish", "topic": d.topic, "msg": to_value(d.message(), cbor=True)})
        text = d.encoded(
            "json", lambda d: json.dumps({"op": "publish", "topic": d.topic, "msg": to_value(d.message())})
        )
        if compression == "png":
            text = json.dumps({"op": "png", "data": png_compress(text)})
        if fragment_size and len(text) > fragment_size:
            pieces = [text[i : i + fragment_size] for i in range(0, len(text), fragment_size)]
            frag_id = f"publish:{d.topic}:{d.stamp_ns}"
            return tuple(
                json.dumps({"op": "fragment", "id": frag_id, "data": p, "num": i, "total": len(pieces)})
                for i, p in enumerate(pieces)
            )
        return text

    return build
