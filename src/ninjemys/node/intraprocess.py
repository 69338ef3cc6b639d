"""In-process delivery (``INTRAPROCESS``): a publisher and a subscriber of one process, like nodelets.

When a Subscription connects to a publisher URI that belongs to a Node of this very process, and one
of its handles was made with ``intraprocess=True``, no socket is opened: an :class:`IntraLink` joins
the Publication to the Subscription and every publish puts a :class:`Handoff` straight into the
subscriber handles' queues (their own threads call back, ``queue_size`` drops the oldest, as over
TCPROS). What a handle receives:

* the publisher's very message object, when the publishing handle *and* the subscriber handle were
  both made with ``intraprocess=True`` and the subscriber uses the publisher's message class (both
  promised: the publisher not to change a message after publishing it, the subscriber not to change
  what it receives; this is roscpp's nodelet contract of ``ConstPtr`` messages);
* otherwise its own copy, decoded from the serialized bytes (serialized once per publish), so code
  that did not opt in never sees a shared object.

Links are made without XML-RPC (the URI is looked up in this process's table of Nodes) and appear in
getBusInfo with the transport name ``INTRAPROCESS``.
"""

from __future__ import annotations

import logging
import threading
import weakref

from ninjemys.wire.tcpros import pack_len

TYPE_CHECKING = False  # importing typing costs ~7 ms of every node's start-up; checkers set it
if TYPE_CHECKING:
    from collections.abc import Mapping
    from typing import Any

    from ninjemys.node.subscriber import Subscription
    from ninjemys.node.topics import Publication

_log = logging.getLogger(__name__)

#: the transport name getBusInfo reports for an in-process connection
INTRAPROCESS = "INTRAPROCESS"

#: slave URI -> the Node of this process that answers it (weak: a dropped Node leaves no entry)
_nodes: weakref.WeakValueDictionary[str, Any] = weakref.WeakValueDictionary()
_nodes_lock = threading.Lock()


def register_node(uri: str, node: Any) -> None:
    """Make ``node`` findable by its slave URI (called once its servers run)."""
    with _nodes_lock:
        _nodes[uri] = node


def unregister_node(uri: str, node: Any) -> None:
    with _nodes_lock:
        if _nodes.get(uri) is node:
            del _nodes[uri]


def is_local_node(name: str) -> bool:
    """True when a live Node of this process has caller id ``name`` (a publisher whose subscriber
    shares its GIL: see ``topics._LAG_YIELD``)."""
    with _nodes_lock:
        nodes = list(_nodes.values())
    return any(node.name == name and not node.is_shutdown for node in nodes)


def local_publication(uri: str, topic: str) -> Publication | None:
    """The Publication of ``topic`` of the Node of this process at ``uri``, or None."""
    with _nodes_lock:
        node = _nodes.get(uri)
    if node is None or node.is_shutdown:
        return None
    pub: Publication | None = node._publications.get(topic)
    return pub


class Handoff:
    """One published message on its way to in-process subscribers: the object (None when the
    publishing handle did not opt in) and, once needed, its serialized body."""

    __slots__ = ("msg", "_body")

    def __init__(self, msg: Any, body: bytes | memoryview | None = None) -> None:
        self.msg = msg
        self._body = body

    def body(self) -> bytes | memoryview:
        """The serialized message (computed once, by whichever thread asks first)."""
        body = self._body
        if body is None:
            msg = self.msg
            if hasattr(msg, "frame_parts"):
                body = memoryview(b"".join(msg.frame_parts()[1]))[4:]
            else:  # a class with only the contract's minimum (docs/CONTRACTS.md)
                body = msg.serialize_to_bytes()
            self._body = body
        return body

    def frame(self) -> bytes:
        """The TCPROS frame (length prefix and body), as a socket subscriber of a latch gets it."""
        body = self.body()
        return pack_len(len(body)) + bytes(body)

    def message_for(self, shared_ok: bool, msg_class: Any) -> Any:
        """What a handle gets: the object itself when it may be shared, else a decoded copy."""
        msg = self.msg
        if shared_ok and msg is not None and type(msg) is msg_class:
            return msg
        return msg_class.deserialize_from(self.body())


class IntraLink:
    """One in-process connection: a Publication's subscriber and a Subscription's publisher at once."""

    intra = True
    fd = -1
    sock = None
    transport = INTRAPROCESS
    latching = False

    def __init__(self, pub: Publication, sub: Subscription, uri: str) -> None:
        from ninjemys.node.topics import connection_ids  # topics imports this module

        self.pub = pub
        self.sub = sub
        self.uri = uri
        self.id = next(connection_ids)
        self.subscriber: str = sub.node.name
        self.publisher: str = pub.node.name
        self.header: Mapping[str, str] = pub.reply_header({"transport": INTRAPROCESS})
        self.latching = self.header.get("latching") == "1"
        self.last: Handoff | None = None
        self.num_sent = self.num_recv = 0
        self.bytes_sent = self.bytes_recv = 0
        self.dropped = 0
        self.closed = False

    def deliver(self, item: Handoff, queue_size: int | None = 0, direct: bool = False) -> None:
        """Put ``item`` in the queue of every open handle of the subscription (publisher's thread).
        ``queue_size`` is the publishing handle's, as over TCPROS (0: a latched replay, never waits);
        ``direct``: a publish, whose thread may call an idle ``direct=True`` handle back itself."""
        if self.closed:
            return
        self.num_sent += 1
        self.num_recv = self.num_sent
        if self.latching:
            self.last = item  # a handle added later replays it, as a socket's last frame
        for handle in self.sub.handles:
            if not handle.closed:
                self.dropped += handle.push_local(item, self.header, queue_size, direct)

    def close(self) -> None:
        """Either end went away (any thread; idempotent): forget the link on both sides."""
        if self.closed:
            return
        self.closed = True
        self.pub.remove_intra(self)
        runtime = self.sub.node.runtime
        runtime.call_soon(self.sub.connection_lost, self, False)


def attach(pub: Publication, sub: Subscription, uri: str) -> IntraLink | None:
    """Join ``sub`` to the in-process ``pub`` (on the loop): None, after one line, on a type mismatch."""
    if sub.md5sum not in ("*", pub.md5sum):
        _log.warning(
            "topic %s: cannot subscribe to %s in-process: it publishes %s (md5 %s), this subscriber wants %s (md5 %s)",
            sub.topic, pub.node.name, pub.type_name, pub.md5sum, sub.type_name, sub.md5sum,
        )  # fmt: skip
        return None
    link = IntraLink(pub, sub, uri)
    pub.add_intra(link)
    return link
