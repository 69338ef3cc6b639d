"""tf2 on a ninjemys :class:`~ninjemys.node.Node`: the listener that fills a buffer from ``/tf`` and
``/tf_static``, the broadcasters, and the ``~tf2_frames`` service.

Wire behaviour is ROS 1's: ``/tf`` and ``/tf_static`` carry ``tf2_msgs/TFMessage``; ``/tf_static`` is
latched and a static broadcaster re-sends every frame it ever sent (tf2_ros's C++ broadcaster keeps
them by child frame; ROS 1's Python one forgets earlier calls, geometry2#406/#455). The listener takes
raw bytes and hands them to the buffer, which decodes them in batches when it is next asked
(:meth:`~ninjemys.tf2.core.BufferCore.add_raw`); the publisher's caller id is the authority, as
tf2_ros records it.
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
        self.tf_sub = node.subscriber(
            "/tf", None, self._on_tf, queue_size=queue_size, raw=True, tcp_nodelay=tcp_nodelay
        )
        # one thread reads both topics (/tf_static is mostly silent: a thread of its own would only wait)
        self.tf_static_sub = node.subscriber(
            "/tf_static",
            None,
            self._on_tf_static,
            queue_size=queue_size,
            raw=True,
            tcp_nodelay=tcp_nodelay,
            share_thread=self.tf_sub,
        )

    def _check_for_reset(self) -> None:
        now = self._now()  # type: ignore[misc]
        with self._reset_lock:
            if now < self._last:
                self._report(f"Detected jump back in time of {self._last - now:f}s. Clearing TF buffer.")
                self.buffer.clear()
            self._last = now

    def _accept(self, raw: Any, topic: str) -> str | None:
        """The publisher's caller id when the message is a TFMessage (one line per publisher otherwise)."""
        header = raw.connection_header
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
        if self._now is not None:
            self._check_for_reset()
        who = self._accept(raw, "/tf")
        if who is not None:
            self.buffer.add_raw(bytes(raw.data), who, False)

    def _on_tf_static(self, raw: Any) -> None:
        if self._now is not None:
            self._check_for_reset()
        who = self._accept(raw, "/tf_static")
        if who is not None:
            self.buffer.add_raw(bytes(raw.data), who, True)

    def unregister(self) -> None:
        """Stop listening (both subscriptions)."""
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
