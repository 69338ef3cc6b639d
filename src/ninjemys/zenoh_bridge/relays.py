"""The four kinds of bridge, as zenoh-plugin-ros1 names them, each relaying bytes it never decodes.

- :class:`RosToZenoh` (a local publisher): a raw ROS subscriber whose messages are put on the data key;
  a latched topic's last message is kept and served to queries on that key (late subscribers across);
- :class:`ZenohToRos` (a local subscriber): a ROS publisher fed by a Zenoh subscriber on the data key;
  on start it asks the key for a latched message and publishes it latched;
- :class:`ServiceToZenoh` (a local service): a queryable whose queries are calls to the service;
- :class:`ZenohToService` (client bridging): a local ROS service whose calls are Zenoh queries.

A latched message travels with the attachment ``latching=1`` (ignored by the Rust bridge, which
sends none). ``<data key>?definition`` answers with the publisher's message definition, so a ROS
publisher on the other side can advertise the real one where the type is unknown there.
"""

from __future__ import annotations

import logging
import threading
from concurrent.futures import ThreadPoolExecutor
from typing import Any

from ninjemys.bag.play import stand_in_class
from ninjemys.errors import NinjemysError, ServiceError
from ninjemys.node import Node
from ninjemys.zenoh_bridge import keys
from ninjemys.zenoh_bridge.keys import Resource
from ninjemys.zenoh_bridge.rosside import local_definition, local_md5

_log = logging.getLogger("ninjemys.zenoh_bridge")

LATCHED = b"latching=1"
QUERY_TIMEOUT = 10.0
DEFINITION_TIMEOUT = 1.0


def raw_service_class(datatype: str, md5: str) -> Any:
    """A service class whose request and response are the serialized bytes, both ways."""

    class RawPart:
        __slots__ = ("payload",)
        _slot_types = ("bytes",)  # not fieldless: an empty body is a payload too

        def __init__(self, payload: bytes = b"") -> None:
            self.payload = payload

        def serialize_to_bytes(self) -> bytes:
            return self.payload

        @classmethod
        def deserialize_from(cls, buf: bytes | bytearray | memoryview) -> RawPart:
            return cls(bytes(buf))

    class RawRequest(RawPart):
        __slots__ = ()
        _type = datatype + "Request"

    class RawResponse(RawPart):
        __slots__ = ()
        _type = datatype + "Response"

    return type(
        "RawService_" + datatype.replace("/", "_"),
        (),
        {"_type": datatype, "_md5sum": md5, "_request_class": RawRequest, "_response_class": RawResponse},
    )


class RosToZenoh:
    """A local publisher's messages, put on Zenoh."""

    def __init__(self, node: Node, session: Any, res: Resource, bridge_ns: str, definition: str = "") -> None:
        self.node, self.res = node, res
        self.key = keys.data_key(res, bridge_ns)
        self._latched: bytes | None = None
        #: from the probe's header, else from the first message's
        self._definition = definition
        self._pub = session.declare_publisher(self.key)
        self._queryable = session.declare_queryable(self.key, self._on_query, complete=False)
        self._sub = node.subscriber(res.name, None, self._on_message, raw=True)

    def _on_message(self, raw: Any) -> None:
        header = raw.connection_header
        if header.get("callerid") == self.node.name:
            return  # our own ZenohToRos publisher on the same topic: never send it back
        if header.get("md5sum", self.res.md5) != self.res.md5:
            return  # another publisher of this topic with another type has its own bridge
        data = bytes(raw.data)
        if not self._definition:
            self._definition = header.get("message_definition", "")
        if header.get("latching") == "1":
            self._latched = data
            self._pub.put(data, attachment=LATCHED)
        else:
            self._pub.put(data)

    def _on_query(self, query: Any) -> None:
        if "definition" in str(query.parameters):
            if self._definition:
                query.reply(self.key, self._definition.encode())
            return
        latched = self._latched
        if latched is not None:
            query.reply(self.key, latched, attachment=LATCHED)

    def close(self) -> None:
        self._sub.unregister()
        for entity in (self._queryable, self._pub):
            _undeclare(entity)


class ZenohToRos:
    """Messages from Zenoh, published to the local subscribers of a topic."""

    def __init__(
        self, node: Node, session: Any, res: Resource, bridge_ns: str, queue_size: int = 100
    ) -> None:
        import zenoh

        self.node, self.res, self.session = node, res, session
        self.key = keys.data_key(res, bridge_ns)
        # the local definition only when it is the same message (md5); else the remote publisher's
        local = local_definition(res.datatype) if local_md5(res.datatype) == res.md5 else None
        definition = local or self._remote_definition() or "*"
        self._cls = stand_in_class(res.datatype, res.md5, definition)
        self._queue_size = queue_size
        self._live = node.publisher(res.name, self._cls, queue_size=queue_size)
        self._latched_pub: Any = None
        self._lock = threading.Lock()
        self._sub = session.declare_subscriber(
            self.key, self._on_sample, allowed_origin=zenoh.Locality.REMOTE
        )
        # a latched message published before this bridge existed: asked for once
        session.get(
            self.key, self._on_reply, timeout=QUERY_TIMEOUT, allowed_destination=zenoh.Locality.REMOTE
        )

    def _remote_definition(self) -> str | None:
        import zenoh

        try:
            for reply in self.session.get(
                self.key + "?definition",
                timeout=DEFINITION_TIMEOUT,
                allowed_destination=zenoh.Locality.REMOTE,
            ):
                if reply.ok is not None:
                    return reply.ok.payload.to_bytes().decode("utf-8", "replace")
        except Exception as exc:
            _log.debug("definition of %s: %s", self.key, exc)
        return None

    def _latched_handle(self) -> Any:
        with self._lock:
            if self._latched_pub is None:
                self._latched_pub = self.node.publisher(
                    self.res.name, self._cls, queue_size=self._queue_size, latch=True
                )
            return self._latched_pub

    def _publish(self, payload: bytes, latched: bool) -> None:
        try:
            (self._latched_handle() if latched else self._live).publish_raw(payload)
        except NinjemysError as exc:  # shutting down
            _log.debug("%s: %s", self.res.name, exc)

    def _on_sample(self, sample: Any) -> None:
        attachment = sample.attachment
        self._publish(sample.payload.to_bytes(), attachment is not None and attachment.to_bytes() == LATCHED)

    def _on_reply(self, reply: Any) -> None:
        ok = reply.ok
        if ok is not None and ok.attachment is not None and ok.attachment.to_bytes() == LATCHED:
            self._publish(ok.payload.to_bytes(), True)

    def close(self) -> None:
        _undeclare(self._sub)
        for handle in (self._live, self._latched_pub):
            if handle is not None:
                handle.unregister()


class ServiceToZenoh:
    """A local service, answering Zenoh queries on its data key."""

    def __init__(
        self, node: Node, session: Any, res: Resource, bridge_ns: str, pool: ThreadPoolExecutor
    ) -> None:
        self.res = res
        self.key = keys.data_key(res, bridge_ns)
        self._cls = raw_service_class(res.datatype, res.md5)
        self._node = node
        self._pool = pool
        self._queryable = session.declare_queryable(self.key, self._on_query, complete=True)

    def _on_query(self, query: Any) -> None:
        # a call can take long: never on Zenoh's own thread
        self._pool.submit(self._answer, query)

    def _answer(self, query: Any) -> None:
        payload = query.payload
        if payload is None:
            query.reply_err(f"service {self.res.name}: a query without a request payload".encode())
            return
        proxy = self._node.service_proxy(self.res.name, self._cls)
        try:
            response = proxy.call(self._cls._request_class(payload.to_bytes()))
        except (NinjemysError, OSError) as exc:
            query.reply_err(str(exc).encode())
            return
        finally:
            proxy.close()
        query.reply(self.key, response.payload)

    def close(self) -> None:
        _undeclare(self._queryable)


class ZenohToService:
    """A remote service provided here, each call a Zenoh query to the bridge that has it."""

    def __init__(self, node: Node, session: Any, res: Resource, bridge_ns: str) -> None:
        self.res, self.session = res, session
        self.key = keys.data_key(res, bridge_ns)
        self._server = node.service(res.name, raw_service_class(res.datatype, res.md5), self._handle)

    def _handle(self, request: Any) -> Any:
        import zenoh

        replies = self.session.get(
            self.key,
            payload=request.payload,
            timeout=QUERY_TIMEOUT,
            target=zenoh.QueryTarget.BEST_MATCHING,
            allowed_destination=zenoh.Locality.REMOTE,
        )
        for reply in replies:
            if reply.ok is not None:
                return self._server.response_class(reply.ok.payload.to_bytes())
            raise ServiceError(reply.err.payload.to_bytes().decode("utf-8", "replace"))
        raise ServiceError(
            f"no bridge answered a call of {self.res.name} on {self.key} within {QUERY_TIMEOUT:g} s"
        )

    def close(self) -> None:
        self._server.shutdown()


def _undeclare(entity: Any) -> None:
    try:
        entity.undeclare()
    except Exception as exc:  # the session is closing already
        _log.debug("undeclare: %s", exc)
