"""tf2 on a ninjemys :class:`~ninjemys.node.Node`: the listener that fills a buffer from ``/tf`` and
``/tf_static``, the broadcasters, and the ``~tf2_frames`` service.

Wire behaviour is ROS 1's: ``/tf`` and ``/tf_static`` carry ``tf2_msgs/TFMessage``; ``/tf_static`` is
latched and a static broadcaster re-sends every frame it ever sent (tf2_ros's C++ broadcaster keeps
them by child frame; ROS 1's Python one forgets earlier calls, geometry2#406/#455). The listener takes
raw bytes and hands them to the buffer, which decodes them in batches when it is next asked
(:meth:`~ninjemys.tf2.core.BufferCore.add_raw`); the publisher's caller id is the authority, as
tf2_ros records it.

The listener's thread does not wake per ``/tf`` message: its subscription is lazy (see
:meth:`ninjemys.node.Node.subscriber`), read every ``LAZY_PERIOD`` seconds or sooner if the socket
would fill, and the buffer pulls what the kernel holds before every query, so a lookup still sees
every message that has arrived. While something waits for data (``can_transform`` with a timeout,
a tf2 MessageFilter) the thread wakes per message, as it also does under simulated time: a jump back
of ``/clock`` clears the buffer, and only messages delivered as they arrive are known to be older or
newer than the jump.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable, Iterable
from typing import Any

from ninjemys.errors import MasterError
from ninjemys.idl.loader import get_message_class, get_service_class
from ninjemys.tf2.buffer import Buffer, to_ns, transform_tuple
from ninjemys.tf2.core import BufferCore
from ninjemys.tf2.wire import encode_tf_message

_log = logging.getLogger(__name__)
TF_MESSAGE_MD5 = "94810edda583a504dfda3829e70d7eec"
#: seconds between the lazy /tf subscription's reads when nobody asks (at most; it adapts down)
LAZY_PERIOD = 0.25


class TransformListener:
    """Subscribes ``/tf`` and ``/tf_static`` on ``node`` and feeds ``buffer``.

    ``now`` (seconds of ROS time) lets the listener notice time jumping back (a bag loop, a sim
    reset): it clears the buffer's non-static data then, as tf2_ros does.
    """

    def __init__(
        self,
        node: Any,
        buffer: BufferCore,
        queue_size: int | None = None,
        tcp_nodelay: bool = False,
        now: Callable[[], float] | None = None,
        report: Callable[[str], None] | None = None,
    ) -> None:
        self.buffer = buffer
        self._now = now
        self._report = report or _log.warning
        self._last = now() if now is not None else 0.0
        self._reset_lock = threading.Lock()
        self._bad_reported: set[str] = set()
        self._tf_header: Any = None  # the connection header of the last /tf message, and its authority
        self._tf_who: str | None = None
        clock = getattr(node, "clock", None)
        self._sim = (lambda: clock.is_sim) if clock is not None else (lambda: False)
        self.tf_sub = node.subscriber(
            "/tf",
            None,
            self._on_tf_batch,
            queue_size=queue_size,
            raw=True,
            tcp_nodelay=tcp_nodelay,
            lazy=LAZY_PERIOD,
            batch=True,
        )
        # one thread reads both topics (/tf_static is mostly silent: a thread of its own would only wait)
        self.tf_static_sub = node.subscriber(
            "/tf_static",
            None,
            self._on_tf_static_batch,
            queue_size=queue_size,
            raw=True,
            tcp_nodelay=tcp_nodelay,
            share_thread=self.tf_sub,
            batch=True,
        )
        # a buffer that pulls before it answers gets the lazy subscription; any other buffer (or a node
        # whose subscriptions cannot be pulled) gets every message as it comes
        add_source = getattr(buffer, "add_source", None)
        self._source = add_source is not None and hasattr(self.tf_sub, "pull")
        if self._source:
            add_source(self)  # type: ignore[misc]
        elif hasattr(self.tf_sub, "set_eager"):
            self.tf_sub.set_eager(True)

    # -- the buffer's source protocol (BufferCore.add_source) ----------------------------------------
    def pull(self) -> None:
        """Deliver what the kernel holds for /tf and /tf_static now (on the caller's thread)."""
        if self._sim():  # (a no-op once the subscription wakes per message)
            self.tf_sub.set_eager(True)
        self.tf_sub.pull()

    def set_eager(self, eager: bool) -> None:
        """Wake per message while ``eager`` (somebody waits for data) or under simulated time."""
        self.tf_sub.set_eager(eager or self._sim())

    def _check_for_reset(self) -> None:
        now = self._now()  # type: ignore[misc]
        with self._reset_lock:
            if now < self._last:
                self._report(f"Detected jump back in time of {self._last - now:f}s. Clearing TF buffer.")
                self.buffer.clear()
            self._last = now

    def _accept(self, header: Any, topic: str) -> str | None:
        """The publisher's caller id when it sends TFMessages (one line per publisher otherwise)."""
        who = header.get("callerid", "default_authority")
        md5 = header.get("md5sum", TF_MESSAGE_MD5)
        if md5 not in (TF_MESSAGE_MD5, "*"):
            if who not in self._bad_reported:
                self._bad_reported.add(who)
                self._report(
                    f"{topic}: {who} publishes type {header.get('type')} (md5 {md5}), not tf2_msgs/TFMessage"
                )
            return None
        return who

    def _on_tf(self, raw: Any) -> None:
        self._on_tf_batch([raw])

    def _on_tf_static(self, raw: Any) -> None:
        self._on_tf_static_batch([raw])

    def _on_tf_batch(self, raws: list[Any]) -> None:
        """Messages read from /tf in one go (all delivered now: one reset check stands for each)."""
        if self._now is not None:
            self._check_for_reset()
        header = raws[0].connection_header
        if header is self._tf_header:  # the same connection as before: already accepted
            who = self._tf_who
        else:
            who = self._tf_who = self._accept(header, "/tf")
            self._tf_header = header
        if len(raws) > 1 and any(r.connection_header is not header for r in raws):
            self._add_each(raws, "/tf", False)
        elif who is not None:
            self.buffer.add_raw_many([bytes(r.data) for r in raws], who, False)

    def _on_tf_static_batch(self, raws: list[Any]) -> None:
        if self._now is not None:
            self._check_for_reset()
        self._add_each(raws, "/tf_static", True)

    def _add_each(self, raws: list[Any], topic: str, static: bool) -> None:
        for raw in raws:
            who = self._accept(raw.connection_header, topic)
            if who is not None:
                self.buffer.add_raw(bytes(raw.data), who, static)

    def unregister(self) -> None:
        """Stop listening (both subscriptions)."""
        if self._source:
            self.buffer.remove_source(self)
        self.tf_sub.unregister()
        self.tf_static_sub.unregister()


def _as_items(transforms: Any) -> list[tuple]:
    """``TransformStamped`` messages (one or a list) as the buffer's tuples."""
    if not isinstance(transforms, (list, tuple)):
        transforms = [transforms]
    return [
        (m.header.frame_id, m.child_frame_id, to_ns(m.header.stamp), *transform_tuple(m.transform))
        for m in transforms
    ]


class TransformBroadcaster:
    """Publishes transforms on ``/tf``."""

    def __init__(self, node: Any, queue_size: int = 100) -> None:
        self.pub_tf = node.publisher("/tf", get_message_class("tf2_msgs/TFMessage"), queue_size=queue_size)

    def sendTransform(self, transform: Any) -> None:  # noqa: N802 (ROS 1's name)
        """Send one ``TransformStamped`` or a list of them, in one message."""
        self.pub_tf.publish_raw(encode_tf_message(_as_items(transform)))

    send_transform = sendTransform

    def send_items(self, items: Iterable[tuple]) -> None:
        """Send ``(parent, child, stamp_ns, 7 floats)`` tuples in one message."""
        self.pub_tf.publish_raw(encode_tf_message(items))

    def unregister(self) -> None:
        self.pub_tf.unregister()


class StaticTransformBroadcaster:
    """Publishes static transforms on the latched ``/tf_static``, re-sending all it has sent."""

    def __init__(self, node: Any, queue_size: int = 100) -> None:
        self.pub_tf = node.publisher(
            "/tf_static", get_message_class("tf2_msgs/TFMessage"), queue_size=queue_size, latch=True
        )
        self._frames: dict[str, tuple] = {}
        self._lock = threading.Lock()

    def sendTransform(self, transform: Any) -> None:  # noqa: N802
        """Add (or replace, by child frame) these transforms and publish the whole set."""
        self.send_items(_as_items(transform))

    send_transform = sendTransform

    def send_items(self, items: Iterable[tuple]) -> None:
        with self._lock:
            for item in items:
                self._frames[item[1]] = tuple(item)
            payload = encode_tf_message(self._frames.values())
            self.pub_tf.publish_raw(payload)

    def unregister(self) -> None:
        self.pub_tf.unregister()


def advertise_frames_service(node: Any, buffer: Buffer, name: str = "~tf2_frames") -> Any:
    """Offer tf2_ros's ``~tf2_frames`` (tf2_msgs/FrameGraph: the buffer's YAML) unless the node already does."""
    resolved = node.resolve_name(name)
    try:
        node.master.lookup_service(resolved)
        return None
    except MasterError:  # not registered yet (or the master cannot say): offer it
        pass
    srv_class = get_service_class("tf2_msgs/FrameGraph")
    return node.service(name, srv_class, lambda _req: srv_class._response_class(buffer.all_frames_as_yaml()))


__all__ = [
    "TransformListener",
    "TransformBroadcaster",
    "StaticTransformBroadcaster",
    "advertise_frames_service",
]
