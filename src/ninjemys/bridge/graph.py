"""The gateway's side of the ROS graph: one core Node shared by every WebSocket client.

- :class:`Taps`: one raw subscription per topic, whatever the number of clients; each message is
  handed, still serialized, to every client's sink on the subscription's own thread. A
  :class:`Delivery` deserializes (or JSON-encodes) at most once, however many clients want it.
- :class:`Publishers`: one publisher per topic shared by the clients that advertise it
  (reference-counted, as rosbridge's publisher manager).
- :class:`Services`: service calls with a type learned by probing the provider, persistent
  connections reused between calls; raw calls (bytes in, bytes out) for Foxglove clients.

Everything here may block on the master or a peer: callers run it off the event loop.
"""

from __future__ import annotations

import functools
import heapq
import itertools
import logging
import threading
import time
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from typing import Any

from ninjemys.errors import NinjemysError, ServiceError
from ninjemys.idl.loader import get_message_class, get_service_class, message_class_from_definition
from ninjemys.node import Node
from ninjemys.node.services import probe
from ninjemys.node.subscriber import RawMessage

log = logging.getLogger(__name__)


def message_class(type_name: str) -> Any:
    """The class of ``type_name``; an unknown type raises NinjemysError naming it."""
    try:
        return get_message_class(type_name)
    except NinjemysError as exc:
        raise NinjemysError(f"unknown message type {type_name}: {exc}") from None


def service_class(type_name: str) -> Any:
    try:
        return get_service_class(type_name)
    except NinjemysError as exc:
        raise NinjemysError(f"unknown service type {type_name}: {exc}") from None


class Delivery:
    """One received message, shared by every client sink: raw bytes, receive time, and lazily
    computed forms (the message object, encoded texts) that are built once."""

    __slots__ = ("topic", "data", "header", "stamp_ns", "msg_class", "_msg", "cache")

    def __init__(self, topic: str, raw: RawMessage, stamp_ns: int, msg_class: Any) -> None:
        self.topic = topic
        self.data = raw.data
        self.header = raw.connection_header
        self.stamp_ns = stamp_ns
        self.msg_class = msg_class
        self._msg: Any = None
        self.cache: dict[Any, Any] = {}

    def message(self) -> Any:
        if self._msg is None:
            cls = self.msg_class
            if cls is None:  # subscribed with md5 "*": the publisher's header says what it is
                type_name = self.header.get("type", "")
                try:
                    cls = get_message_class(type_name)
                except NinjemysError:
                    cls = message_class_from_definition(
                        type_name, self.header.get("message_definition", ""), self.header.get("md5sum")
                    )
            self._msg = cls.deserialize_from(bytes(self.data))
        return self._msg

    def encoded(self, key: Any, build: Callable[[Delivery], Any]) -> Any:
        """``build(self)`` once per ``key`` (a tap feeds its sinks one at a time, under its lock)."""
        try:
            return self.cache[key]
        except KeyError:
            value = self.cache[key] = build(self)
            return value


Sink = Callable[[Delivery], None]


class _Tap:
    """One raw subscription and the sinks it feeds.

    Latched messages reach every sink, as each ROS subscriber gets them: the first sink is in place
    before the subscription exists (a latched publisher's message can arrive on the subscription's
    thread before ``node.subscriber`` returns, and it is sent once per connection: a sink added a
    moment later missed it, and a browser switching to a latched topic never got a frame), and a
    sink joining a running tap is first given the last message of each latched publisher still
    connected. ``_lock`` makes "add a sink, replay" and "deliver to every sink" exclusive, so a
    joining sink gets each message once and in order."""

    def __init__(
        self, node: Node, topic: str, msg_class: Any, clock: Callable[[], int], owner: object, sink: Sink
    ) -> None:
        self.topic = topic
        self.msg_class = msg_class
        self.sinks: dict[object, Sink] = {owner: sink}
        self._clock = clock
        self._lock = threading.Lock()
        self._latched: dict[str, Delivery] = {}  # publisher caller id -> its last message
        self.sub = node.subscriber(topic, msg_class, self._on_message, raw=True, queue_size=100)

    def _on_message(self, raw: RawMessage) -> None:
        delivery = Delivery(self.topic, raw, self._clock(), self.msg_class)
        with self._lock:
            if raw.connection_header.get("latching") == "1":
                self._latched[raw.connection_header.get("callerid", "")] = delivery
            for sink in list(self.sinks.values()):
                _feed(sink, delivery)

    def join(self, owner: object, sink: Sink) -> None:
        """Add ``sink``; it gets the latched messages of the publishers connected now first."""
        with self._lock:
            self.sinks[owner] = sink
            live = self.sub.publisher_ids()
            for caller_id, delivery in list(self._latched.items()):
                if caller_id in live:
                    _feed(sink, delivery)
                else:
                    del self._latched[caller_id]  # that publisher left: a new subscriber would not get it


def _feed(sink: Sink, delivery: Delivery) -> None:
    try:
        sink(delivery)
    except Exception as exc:  # one client's bad state must not stop the others
        log.warning("gateway: delivering %s failed: %s", delivery.topic, exc)


class Taps:
    """Raw subscriptions shared by all clients, keyed by topic."""

    def __init__(self, node: Node, clock: Callable[[], int]) -> None:
        self.node = node
        self._clock = clock
        self._taps: dict[str, _Tap] = {}
        self._lock = threading.Lock()

    def add(
        self, topic: str, type_name: str | None, owner: object, sink: Sink, published_as: str | None = None
    ) -> str:
        """Start delivering ``topic`` to ``sink``; returns the type used. Raises NinjemysError when the
        type is unknown or differs from the one the gateway already subscribed with. A type we cannot
        load is still accepted when it is what the topic is ``published_as``: the tap then subscribes
        with md5 ``*`` and decodes from the publisher's ``message_definition`` when it must."""
        with self._lock:
            tap = self._taps.get(topic)
            if tap is None:
                msg_class = None
                if type_name and type_name != "*":
                    try:
                        msg_class = message_class(type_name)
                    except NinjemysError:
                        if type_name != published_as:
                            raise
                tap = self._taps[topic] = _Tap(self.node, topic, msg_class, self._clock, owner, sink)
            elif type_name and tap.msg_class is not None and type_name not in ("*", tap.msg_class._type):
                raise NinjemysError(f"topic {topic} is subscribed as {tap.msg_class._type}, not {type_name}")
            else:
                tap.join(owner, sink)
            return tap.msg_class._type if tap.msg_class is not None else (type_name or "*")

    def remove(self, topic: str, owner: object) -> None:
        with self._lock:
            tap = self._taps.get(topic)
            if tap is None:
                return
            tap.sinks.pop(owner, None)
            if not tap.sinks:
                del self._taps[topic]
                tap.sub.unregister()

    def topics(self) -> list[str]:
        with self._lock:
            return list(self._taps)


class Publishers:
    """Publishers shared by the clients advertising a topic (reference-counted per owner)."""

    def __init__(self, node: Node) -> None:
        self.node = node
        self._pubs: dict[str, tuple[Any, Any, set[object]]] = {}
        self._lock = threading.Lock()

    def advertise(
        self,
        topic: str,
        type_name: str,
        owner: object,
        latch: bool = False,
        queue_size: int = 100,
        msg_class: Any = None,
    ) -> Any:
        """The publisher for ``topic`` (created on first use); raises NinjemysError on a type clash.
        ``msg_class`` is given for a type learned from a client's definition (:meth:`learn`)."""
        msg_class = msg_class or message_class(type_name)
        with self._lock:
            entry = self._pubs.get(topic)
            if entry is None:
                pub = self.node.publisher(topic, msg_class, queue_size=queue_size, latch=latch)
                entry = self._pubs[topic] = (pub, msg_class, set())
            elif entry[1]._md5sum != msg_class._md5sum:
                raise NinjemysError(
                    f"topic {topic} is already advertised as {entry[1]._type}, not {type_name}"
                )
            entry[2].add(owner)
            return entry[0]

    @staticmethod
    def learn(type_name: str, definition: str) -> Any:
        """The class of ``type_name``, built from its full definition text when the type is neither
        shipped nor on the package path (a Foxglove client may advertise its own types)."""
        try:
            return get_message_class(type_name)
        except NinjemysError:
            try:
                return message_class_from_definition(type_name, definition)
            except NinjemysError as exc:
                raise NinjemysError(f"cannot use the definition of {type_name}: {exc}") from None

    def get(self, topic: str) -> tuple[Any, Any] | None:
        entry = self._pubs.get(topic)
        return None if entry is None else (entry[0], entry[1])

    def unadvertise(self, topic: str, owner: object) -> None:
        with self._lock:
            entry = self._pubs.get(topic)
            if entry is None:
                return
            entry[2].discard(owner)
            if not entry[2]:
                del self._pubs[topic]
                entry[0].unregister()


@functools.cache
def _raw_service_class(type_name: str, md5sum: str) -> Any:
    """A service class whose request is bytes already serialized and whose response stays bytes
    (Foxglove's service calls carry ROS 1 bytes both ways: nothing is decoded in the gateway).
    One class per (type, md5sum): the persistent proxy is cached by them and only takes requests
    of its own request class (a new class per call made every call after the first fail)."""

    class RawRequest:
        _type = type_name + "Request"
        __slots__ = ("payload",)

        def __init__(self, payload: bytes = b"") -> None:
            self.payload = payload

        def serialize_to_bytes(self) -> bytes:
            return self.payload

    class RawResponse:
        _type = type_name + "Response"

        @classmethod
        def deserialize_from(cls, buf: bytes | bytearray | memoryview) -> bytes:
            return bytes(buf)

    class RawService:
        _type = type_name
        _md5sum = md5sum
        _request_class = RawRequest
        _response_class = RawResponse

    return RawService


class Services:
    """Service calls through the gateway's node: typed (rosbridge) and raw (Foxglove)."""

    #: calls to one service in flight at once (each on its own connection, as rosbridge's per-call threads)
    LANE_WORKERS = 4

    def __init__(self, node: Node) -> None:
        self.node = node
        self._types: dict[str, tuple[str, dict[str, str]]] = {}  # service -> (uri, provider header)
        # one connection per (service, type, raw, lane thread): a hung call holds only its own
        self._proxies: dict[tuple[str, str, bool, int], Any] = {}
        self._lock = threading.Lock()
        self._lanes: dict[str, ThreadPoolExecutor] = {}
        self._deadlines = _Deadlines()
        self._closed = False

    def dispatch(
        self,
        service: str,
        timeout: float | None,
        work: Callable[[Callable[[], bool]], None],
        on_timeout: Callable[[], None],
    ) -> None:
        """Run one client's call on ``service``'s own lane, answered within ``timeout`` seconds.

        Each service has its own small pool (a lane), so calls that hang on one service (a stuck
        provider, a hostile client calling it over and over) hold only that lane: calls to every
        other service still start at once. ``work(claim)`` makes the call and, before it answers,
        calls ``claim()``: True when it is first, False when the deadline already answered (then it
        must stay silent). At the deadline ``on_timeout()`` runs, unless the work claimed first. A
        call that hangs keeps its lane thread until the provider answers or goes away (a blocked
        socket read cannot be interrupted safely), which is why the lanes are per service."""
        answered = threading.Lock()

        def claim() -> bool:
            return answered.acquire(blocking=False)

        def expire() -> None:
            if claim():
                on_timeout()

        def run() -> None:
            if answered.locked():  # its deadline passed while it waited in the lane
                return
            work(claim)

        with self._lock:
            if self._closed:
                raise ServiceError("the gateway is shutting down")
            lane = self._lanes.get(service)
            if lane is None:
                lane = self._lanes[service] = ThreadPoolExecutor(
                    self.LANE_WORKERS, thread_name_prefix=f"gateway-call {service}"
                )
        if timeout is not None and timeout > 0:
            self._deadlines.add(time.monotonic() + timeout, expire)
        lane.submit(run)

    def provider_header(self, service: str, fresh: bool = False) -> dict[str, str]:
        """The provider's connection header (``type``, ``md5sum``), probed once per provider.

        Kept until a call on a persistent connection to the provider fails (``_call`` then asks with
        ``fresh=True``): looking the provider up on the master for every call cost an XML-RPC round
        trip per rosbridge call without a ``type`` (roslibjs and roslibpy never send one), about a
        tenth of the gateway's CPU per call, and told nothing a live connection does not."""
        cached = self._types.get(service)
        if cached is not None and not fresh:
            return cached[1]
        try:
            uri = self.node.master.lookup_service(service)
        except NinjemysError as exc:
            raise ServiceError(f"service {service} does not exist: {exc}") from None
        if cached is not None and cached[0] == uri:
            return cached[1]
        try:
            header = probe(service, uri, timeout=5.0)
        except NinjemysError as exc:
            raise ServiceError(str(exc)) from None
        if "error" in header:
            raise ServiceError(f"service {service}: {header['error']}")
        self._types[service] = (uri, header)
        return header

    def service_type(self, service: str) -> str:
        return self.provider_header(service).get("type", "")

    def _proxy(self, service: str, service_class: Any, raw: bool) -> Any:
        key = (service, service_class._md5sum, raw, threading.get_ident())
        with self._lock:
            proxy = self._proxies.get(key)
            if proxy is None:
                proxy = self._proxies[key] = self.node.service_proxy(service, service_class, persistent=True)
            return proxy

    def _call(self, service: str, raw: bool, prepare: Callable[[], tuple[Any, Any]]) -> Any:
        """Call ``service`` with what ``prepare()`` gives: (service class, request).

        A persistent connection to a provider that restarted fails once: the provider is then looked
        up and probed again, ``prepare()`` runs again (a provider of another type gets a request of
        its type, when the caller named none) and the call goes out once more on a new connection."""
        service_class, request = prepare()
        proxy = self._proxy(service, service_class, raw)
        try:
            return proxy.call(request)
        except ServiceError as exc:
            if "transport error" not in str(exc) and "handshake failed" not in str(exc):
                raise
            with self._lock:
                self._proxies.pop((service, service_class._md5sum, raw, threading.get_ident()), None)
            proxy.close()
            self.provider_header(service, fresh=True)  # a service that is gone now says so here
            service_class, request = prepare()
            return self._proxy(service, service_class, raw).call(request)

    def call(self, service: str, type_name: str | None, build_request: Callable[[Any], Any]) -> Any:
        """Call ``service``; ``build_request(request_class)`` makes the request. Returns the response."""

        def prepare() -> tuple[Any, Any]:
            cls = service_class(type_name or self.service_type(service))
            return cls, build_request(cls._request_class)

        return self._call(service, False, prepare)

    def call_raw(self, service: str, payload: bytes) -> bytes:
        """Call ``service`` with a request already serialized; returns the response's bytes."""

        def prepare() -> tuple[Any, Any]:
            header = self.provider_header(service)
            cls = _raw_service_class(header.get("type", ""), header.get("md5sum", "*"))
            return cls, cls._request_class(payload)

        result: bytes = self._call(service, True, prepare)
        return result

    def close(self) -> None:
        """Stop the lanes and close the connections; never waits for a call that hangs (closing a
        proxy waits for its call, so that runs on a daemon thread)."""
        with self._lock:
            self._closed = True
            proxies = list(self._proxies.values())
            self._proxies.clear()
            lanes = list(self._lanes.values())
            self._lanes.clear()
        self._deadlines.stop()
        for lane in lanes:
            lane.shutdown(wait=False, cancel_futures=True)

        def close_all() -> None:
            for proxy in proxies:
                proxy.close()

        threading.Thread(target=close_all, name="gateway-proxies-close", daemon=True).start()


class _Deadlines:
    """One thread that runs callbacks at their deadlines (a heap), so a call's bounded wait costs
    an entry here, not a thread of its own."""

    def __init__(self) -> None:
        self._heap: list[tuple[float, int, Callable[[], None]]] = []
        self._seq = itertools.count()
        self._cond = threading.Condition()
        self._thread: threading.Thread | None = None
        self._stopped = False

    def add(self, when: float, callback: Callable[[], None]) -> None:
        with self._cond:
            if self._stopped:
                return
            heapq.heappush(self._heap, (when, next(self._seq), callback))
            if self._thread is None:
                self._thread = threading.Thread(target=self._run, name="gateway-deadlines", daemon=True)
                self._thread.start()
            self._cond.notify()

    def stop(self) -> None:
        with self._cond:
            self._stopped = True
            self._heap.clear()
            self._cond.notify()

    def _run(self) -> None:
        while True:
            with self._cond:
                while not self._stopped and (not self._heap or self._heap[0][0] > time.monotonic()):
                    self._cond.wait(self._heap[0][0] - time.monotonic() if self._heap else None)
                if self._stopped:
                    return
                callback = heapq.heappop(self._heap)[2]
            try:
                callback()
            except Exception:  # one client's reply failing must not stop everyone's deadlines
                log.exception("gateway: service call deadline handler failed")


def wall_ns() -> int:
    return time.time_ns()
