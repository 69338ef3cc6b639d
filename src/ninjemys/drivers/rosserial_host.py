"""The host side of rosserial: a device's topics, services, parameters, logs and clock on a ROS node.

One :class:`RosserialHost` serves one link (a serial port or a TCP connection, anything with
``read``/``write``/``close``). On start and whenever sync is lost it asks the device for its topics; the
device answers with one ``rosserial_msgs/TopicInfo`` per publisher, subscriber and service endpoint,
and the host advertises, subscribes or provides each under the device's names, after checking that
the device's md5sum is the one of the type the host knows. Then it relays:

* device publisher -> ``publish_raw`` of the payload (the device already serialized it);
* ROS subscriber -> the serialized message, framed, to the device (raw subscription, no decoding);
* ``ID_TIME`` -> the host's ``std_msgs/Time`` back: the device's clock sync, and the link's heartbeat;
* ``ID_PARAMETER_REQUEST`` -> ``rosserial_msgs/RequestParam`` response from the parameter server;
* ``ID_LOG`` -> the node's logger at the device's level, so it reaches ``/rosout``;
* device service servers: a ROS service whose calls go to the device and wait for its answer;
* device service clients: the device's requests call the ROS service and its answer goes back.

With no time sync for ``sync_timeout`` seconds (rosserial_python: 3 x 5 s) the host logs ROS 1's
"Lost sync with device, restarting..." (or, if no good packet ever came on this link, "Unable to sync
with device; ...") and asks for the topics again; bad packets are dropped with
rosserial_python's log lines and never stop the link.
"""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass, field
from typing import Any, Protocol

from ninjemys.drivers import rosserial_protocol as proto
from ninjemys.errors import NinjemysError
from ninjemys.idl.loader import get_message_class, get_service_class

#: how long a call to a device's service waits for the device's answer
SERVICE_TIMEOUT = 5.0
#: rosserial_python's default: 3 x its 5 s timeout without time sync means the link is lost
SYNC_TIMEOUT = 15.0
#: the messages of rosserial_python's /diagnostics statuses
ERROR_MISMATCHED_PROTOCOL = (
    "Mismatched protocol version in packet: lost sync or rosserial_python is from different ros release "
    "than the rosserial client"
)
ERROR_NO_SYNC = "no sync with device"


class Transport(Protocol):
    """What the host needs of a link: reads that time out (returning b""), writes, close."""

    def read(self, size: int) -> bytes: ...
    def write(self, data: bytes) -> Any: ...
    def close(self) -> None: ...


class RosserialError(NinjemysError):
    """A device announced something the host cannot serve (unknown type, md5 mismatch)."""


@dataclass
class _DeviceService:
    """One service endpoint pair on the device; ``request_id``/``response_id`` fill in as they arrive."""

    name: str
    type_name: str
    request_id: int | None = None
    response_id: int | None = None
    handle: Any = None
    lock: threading.Lock = field(default_factory=threading.Lock)  # one call at a time, as on the device
    answer: threading.Condition = field(default_factory=threading.Condition)
    response: bytes | None = None


def _topic_info_class() -> Any:
    return get_message_class("rosserial_msgs/TopicInfo")


class RosserialHost:
    """Serve one device link on ``node`` until the node shuts down or the link fails (then ``run`` returns)."""

    def __init__(self, node: Any, link: Transport, sync_timeout: float = SYNC_TIMEOUT) -> None:
        self.node = node
        self.log = node.log
        self.link = link
        self.sync_timeout = sync_timeout
        self.reader = proto.FrameReader()
        self._write_lock = threading.Lock()
        self.TopicInfo: Any = _topic_info_class()
        self.Log: Any = get_message_class("rosserial_msgs/Log")
        self.Time: Any = get_message_class("std_msgs/Time")
        self.RequestParam: Any = get_service_class("rosserial_msgs/RequestParam")
        self.publishers: dict[int, Any] = {}  # topic id -> Publisher
        self.subscribers: dict[int, Any] = {}  # topic id -> Subscriber
        self._pub_by_name: dict[str, tuple[str, Any]] = {}
        self._sub_by_name: dict[str, tuple[int, str, Any]] = {}
        self.services: dict[str, _DeviceService] = {}
        self._service_by_id: dict[int, _DeviceService] = {}
        self.clients: dict[int, tuple[Any, int | None]] = {}  # request id -> (proxy, response id)
        self._client_by_name: dict[str, dict[str, Any]] = {}
        self.synced = False
        self.last_sync = time.monotonic()
        self._last_unknown_request = 0.0
        self._pub_buffer_noted = False
        self._sub_buffer_noted = False
        self.buffer_in = -1  # the device's input buffer, from its first subscriber's TopicInfo
        self.frames_in = 0
        self.dropped = 0
        self.DiagnosticArray: Any = get_message_class("diagnostic_msgs/DiagnosticArray")
        self.DiagnosticStatus: Any = get_message_class("diagnostic_msgs/DiagnosticStatus")
        self.KeyValue: Any = get_message_class("diagnostic_msgs/KeyValue")
        self.diagnostics = node.publisher("/diagnostics", self.DiagnosticArray, queue_size=10)
        self.last_sync_wall = time.time()  # "last sync" and "last sync lost" in the diagnostics
        self.last_sync_lost_wall = 0.0

    # -- the link ------------------------------------------------------------------------------------

    def send(self, topic_id: int, payload: bytes | bytearray = b"") -> None:
        """Frame and write ``payload``; one larger than the device's input buffer (the size its
        subscribers announced) is dropped with rosserial_python's error, as it would overrun the board."""
        if 0 < self.buffer_in < len(payload):
            self.log.error(
                "Message from ROS network dropped: message larger than buffer. (%d bytes on topic id %d, "
                "the device's buffer holds %d)",
                len(payload),
                topic_id,
                self.buffer_in,
            )
            return
        packet = proto.frame(topic_id, payload)
        with self._write_lock:
            self.link.write(packet)

    def request_topics(self) -> None:
        self.log.info("Requesting topics...")
        with self._write_lock:
            self.link.write(proto.REQUEST_TOPICS)

    def run(self) -> None:
        """Read and dispatch until shutdown; an OSError of the link ends the run (the caller reconnects)."""
        self.request_topics()
        self.last_sync = time.monotonic()
        try:
            while not self.node.is_shutdown:
                # what is there, or wait (up to the link's timeout) for one byte: a read of a fixed size
                # would hold a short packet back until the timeout
                waiting = getattr(self.link, "in_waiting", 0)
                data = self.link.read(waiting if waiting else 1)
                if data:
                    for item in self.reader.feed(data):
                        if isinstance(item, proto.Drop):
                            self.dropped += 1
                            if item.reason is proto.DropReason.VERSION:
                                self.send_diagnostics(ERROR_MISMATCHED_PROTOCOL)
                            for level, line in item.log_lines():
                                (self.log.error if level == "error" else self.log.info)("%s", line)
                        else:
                            self.frames_in += 1
                            self.synced = True  # any good packet, as rosserial_python counts it
                            self._dispatch(item)
                now = time.monotonic()
                if now - self.last_sync > self.sync_timeout:
                    if self.synced:
                        self.log.error("Lost sync with device, restarting...")
                    else:
                        self.log.error(
                            "Unable to sync with device; possible link problem or link software version "
                            "mismatch such as hydro rosserial_python with groovy Arduino"
                        )
                    self.last_sync_lost_wall = time.time()
                    self.send_diagnostics(ERROR_NO_SYNC)
                    self.request_topics()
                    self.last_sync = now
        finally:
            if self.node.is_shutdown:
                try:
                    with self._write_lock:
                        self.link.write(proto.TX_STOP)
                    self.log.info("Sending tx stop request")
                except OSError:
                    pass

    def send_diagnostics(self, text: str) -> None:
        """An ERROR status on ``/diagnostics``, as rosserial_python sends on a lost sync or a packet of
        another protocol version: name ``rosserial_python``, with the last sync and last loss."""
        status = self.DiagnosticStatus()
        status.name = "rosserial_python"
        status.level = self.DiagnosticStatus.ERROR
        status.message = text
        status.values = [
            self.KeyValue(key="last sync", value=time.ctime(self.last_sync_wall)),
            self.KeyValue(key="last sync lost", value=time.ctime(self.last_sync_lost_wall)),
        ]
        msg = self.DiagnosticArray()
        msg.header.stamp = self.node.now()
        msg.status = [status]
        self.diagnostics.publish(msg)

    def close(self) -> None:
        """Release what this link set up on the node (the node itself stays up for a reconnect)."""
        for pub in self.publishers.values():
            pub.unregister()
        for sub in self.subscribers.values():
            sub.unregister()
        for svc in self.services.values():
            if svc.handle is not None:
                self.node.release_service(svc.handle)
        self.publishers.clear()
        self.subscribers.clear()
        self.services.clear()
        self.diagnostics.unregister()

    # -- dispatch -------------------------------------------------------------------------------------

    def _dispatch(self, f: proto.Frame) -> None:
        tid = f.topic_id
        try:
            if tid == proto.ID_PUBLISHER:
                self._setup_publisher(self._topic_info(f.payload))
            elif tid == proto.ID_SUBSCRIBER:
                self._setup_subscriber(self._topic_info(f.payload))
            elif tid in (proto.ID_SERVICE_SERVER, proto.ID_SERVICE_SERVER + 1):
                self._setup_service_server(self._topic_info(f.payload), tid == proto.ID_SERVICE_SERVER)
            elif tid in (proto.ID_SERVICE_CLIENT, proto.ID_SERVICE_CLIENT + 1):
                self._setup_service_client(self._topic_info(f.payload), tid == proto.ID_SERVICE_CLIENT)
            elif tid == proto.ID_TIME:
                self._handle_time()
            elif tid == proto.ID_PARAMETER_REQUEST:
                self._handle_parameter_request(f.payload)
            elif tid == proto.ID_LOG:
                self._handle_log(f.payload)
            elif tid in self.publishers:
                self.publishers[tid].publish_raw(f.payload)
            elif tid in self._service_by_id:
                self._service_answer(self._service_by_id[tid], f.payload)
            elif tid in self.clients:
                threading.Thread(
                    target=self._call_for_device, args=(tid, f.payload), name="rosserial-call", daemon=True
                ).start()
            else:
                now = time.monotonic()
                if now - self._last_unknown_request > 1.0:
                    self._last_unknown_request = now
                    self.log.error("Tried to publish before configured, topic id %d", tid)
                    self.request_topics()
        except RosserialError as exc:
            self.log.error("%s", exc)
        except Exception as exc:  # a malformed payload from the device must not stop the link
            self.log.error("rosserial: bad packet on topic id %d: %s", tid, exc)

    def _topic_info(self, payload: bytes) -> Any:
        return self.TopicInfo().deserialize(payload)

    @staticmethod
    def _checked_class(kind: str, info: Any) -> Any:
        try:
            cls = get_message_class(info.message_type)
        except NinjemysError as exc:
            raise RosserialError(f"Creation of {kind} failed: {exc}") from None
        if cls._md5sum != info.md5sum:
            raise RosserialError(
                f"Creation of {kind} failed: Checksum does not match: {cls._md5sum},{info.md5sum} "
                f"({info.topic_name} [{info.message_type}])"
            )
        return cls

    def _setup_publisher(self, info: Any) -> None:
        cls = self._checked_class("publisher", info)
        known = self._pub_by_name.get(info.topic_name)
        if known is not None and known[0] == cls._md5sum:
            pub = known[1]
        else:
            if known is not None:
                known[1].unregister()
            pub = self.node.publisher(info.topic_name, cls, queue_size=10)
            self._pub_by_name[info.topic_name] = (cls._md5sum, pub)
        self.publishers = {k: v for k, v in self.publishers.items() if v is not pub}
        self.publishers[info.topic_id] = pub
        self.log.info("Setup publisher on %s [%s]", info.topic_name, info.message_type)
        if not self._pub_buffer_noted and info.buffer_size:
            self._pub_buffer_noted = True
            self.log.info("Note: publish buffer size is %d bytes", info.buffer_size)

    def _setup_subscriber(self, info: Any) -> None:
        cls = self._checked_class("subscriber", info)
        known = self._sub_by_name.get(info.topic_name)
        if known is not None and known[1] == cls._md5sum and known[0] == info.topic_id:
            self.log.info("Setup subscriber on %s [%s]", info.topic_name, info.message_type)
            return
        if known is not None:
            known[2].unregister()
            self.subscribers.pop(known[0], None)
        topic_id = info.topic_id

        def forward(raw: Any) -> None:
            try:
                self.send(topic_id, raw.data)
            except OSError as exc:
                self.log.warn("rosserial: could not write to the device: %s", exc)

        sub = self.node.subscriber(info.topic_name, cls, forward, raw=True, queue_size=10)
        self._sub_by_name[info.topic_name] = (topic_id, cls._md5sum, sub)
        self.subscribers[topic_id] = sub
        self.log.info("Setup subscriber on %s [%s]", info.topic_name, info.message_type)
        if not self._sub_buffer_noted and info.buffer_size:
            self._sub_buffer_noted = True
            self.buffer_in = info.buffer_size
            self.log.info("Note: subscribe buffer size is %d bytes", info.buffer_size)

    def _service_class(self, kind: str, info: Any) -> Any:
        try:
            cls: Any = get_service_class(info.message_type)
        except NinjemysError as exc:
            raise RosserialError(f"Creation of {kind} failed: {exc}") from None
        if cls._md5sum != info.md5sum:
            raise RosserialError(
                f"Creation of {kind} failed: Checksum does not match: {cls._md5sum},{info.md5sum} "
                f"({info.topic_name} [{info.message_type}])"
            )
        return cls

    def _setup_service_server(self, info: Any, device_publishes: bool) -> None:
        """A service the device provides: its publisher sends responses, its subscriber takes requests."""
        cls = self._service_class("service server", info)
        svc = self.services.get(info.topic_name)
        if svc is None or svc.type_name != info.message_type:
            if svc is not None and svc.handle is not None:
                self.node.release_service(svc.handle)
            svc = _DeviceService(info.topic_name, info.message_type)
            self.services[info.topic_name] = svc
        if device_publishes:
            svc.response_id = info.topic_id
            self._service_by_id[info.topic_id] = svc
        else:
            svc.request_id = info.topic_id
        if svc.handle is None:
            svc.handle = self.node.service(
                info.topic_name, cls, lambda req, s=svc, c=cls: self._call_device(s, c, req)
            )
        self.log.info("Setup service server on %s [%s]", info.topic_name, info.message_type)

    def _call_device(self, svc: _DeviceService, cls: Any, request: Any) -> Any:
        if svc.request_id is None or svc.response_id is None:
            raise RosserialError(f"service {svc.name}: the device has not announced both of its endpoints")
        with svc.lock:
            with svc.answer:
                svc.response = None
            self.send(svc.request_id, request.serialize_to_bytes())
            with svc.answer:
                if not svc.answer.wait_for(lambda: svc.response is not None, SERVICE_TIMEOUT):
                    raise RosserialError(
                        f"service {svc.name}: no response from the device in {SERVICE_TIMEOUT} s"
                    )
                data, svc.response = svc.response, None
        return cls._response_class().deserialize(data)

    def _service_answer(self, svc: _DeviceService, payload: bytes) -> None:
        with svc.answer:
            svc.response = payload
            svc.answer.notify_all()

    def _setup_service_client(self, info: Any, device_publishes: bool) -> None:
        """A service the device calls: its publisher sends requests, its subscriber takes responses."""
        cls = self._service_class("service client", info)
        entry = self._client_by_name.setdefault(info.topic_name, {"cls": cls})
        if device_publishes:
            entry["request_id"] = info.topic_id
        else:
            entry["response_id"] = info.topic_id
        if "request_id" in entry:
            proxy = entry.get("proxy") or self.node.service_proxy(info.topic_name, cls)
            entry["proxy"] = proxy
            self.clients[entry["request_id"]] = (proxy, entry.get("response_id"))
        self.log.info("Setup service client on %s [%s]", info.topic_name, info.message_type)

    def _call_for_device(self, request_id: int, payload: bytes) -> None:
        proxy, response_id = self.clients[request_id]
        if response_id is None:
            self.log.error("rosserial: the device called a service before announcing where answers go")
            return
        try:
            request = proxy.request_class().deserialize(payload)
            response = proxy(request)
            self.send(response_id, response.serialize_to_bytes())
        except Exception as exc:  # the device waits in vain, as with rosserial_python
            self.log.error("rosserial: service call for the device failed: %s", exc)

    # -- protocol topics -------------------------------------------------------------------------------

    def _handle_time(self) -> None:
        msg = self.Time()
        msg.data = self.node.now()
        self.send(proto.ID_TIME, msg.serialize_to_bytes())
        self.last_sync_wall = time.time()
        self.last_sync = time.monotonic()

    def _handle_parameter_request(self, payload: bytes) -> None:
        req = self.RequestParam._request_class().deserialize(payload)
        if not self.node.has_param(req.name):
            self.log.error("Parameter %s does not exist", req.name)
            return
        value = self.node.get_param(req.name)
        resp = self.RequestParam._response_class()
        try:
            resp.ints, resp.floats, resp.strings = param_response_lists(value)
        except RosserialError as exc:
            self.log.error("%s", str(exc).replace("{name}", req.name))
            return
        self.send(proto.ID_PARAMETER_REQUEST, resp.serialize_to_bytes())

    def _handle_log(self, payload: bytes) -> None:
        msg = self.Log().deserialize(payload)
        emit: Any = {
            0: self.log.debug,
            1: self.log.info,
            2: self.log.warn,
            3: self.log.error,
            4: self.log.fatal,
        }.get(msg.level)
        if emit is not None:  # another level is dropped, as rosserial_python drops it
            emit("%s", msg.msg)


def param_response_lists(value: Any) -> tuple[list[int], list[float], list[str]]:
    """A parameter as RequestParam's (ints, floats, strings): a scalar or a list of one kind.

    Booleans travel as ints (rosserial_python's rule, since bool is an int); dictionaries and mixed lists
    cannot be sent (``{name}`` in the error is filled in by the caller).
    """
    if isinstance(value, dict):
        raise RosserialError("Cannot send param {name} because it is a dictionary")
    values = list(value) if isinstance(value, list | tuple) else [value]
    if not values:
        return [], [], []
    kinds = {type(v) for v in values}  # rosserial_python compares exact types: [1, True] is mixed
    if len(kinds) != 1:
        raise RosserialError("All Paramers in the list {name} must be of the same type")
    kind = kinds.pop()
    if kind is int or kind is bool:
        return [int(v) for v in values], [], []
    if kind is float:
        return [], [float(v) for v in values], []
    if kind is str:
        return [], [], list(values)
    raise RosserialError(f"Parameter {{name}} has a type rosserial cannot send ({kind.__name__})")
