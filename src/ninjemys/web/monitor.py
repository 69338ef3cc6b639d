"""Live facts about a topic for the graph page: message rate and the last message, like rostopic hz/echo.

A topic is watched only while somebody looks at it: the first request subscribes (raw, so any type
works, including ones we do not ship: the publisher's ``message_definition`` decodes it), and a topic
nobody asked about for :data:`IDLE_TIMEOUT` seconds is unsubscribed again. Messages are counted as
bytes; only the last one is decoded, and only when asked for.
"""

from __future__ import annotations

import threading
import time
from collections import deque
from collections.abc import Callable
from typing import Any

from ninjemys.errors import NinjemysError

#: seconds over which the rate is averaged (rostopic hz uses a window of messages; time is steadier here)
RATE_WINDOW = 10.0
#: stop watching a topic nobody asked about for this long
IDLE_TIMEOUT = 10.0
#: the last message is shown up to this many characters
MESSAGE_LIMIT = 4000


class _Watch:
    def __init__(self, subscriber: Any) -> None:
        self.subscriber = subscriber
        self.stamps: deque[float] = deque()
        self.count = 0
        self.last: Any = None
        self.asked = time.monotonic()
        self.lock = threading.Lock()

    def on_message(self, raw: Any) -> None:
        now = time.monotonic()
        with self.lock:
            self.count += 1
            self.last = raw
            self.stamps.append(now)
            while self.stamps and now - self.stamps[0] > RATE_WINDOW:
                self.stamps.popleft()

    def rate(self) -> float | None:
        with self.lock:
            now = time.monotonic()
            while self.stamps and now - self.stamps[0] > RATE_WINDOW:
                self.stamps.popleft()
            if len(self.stamps) < 2:
                return None
            span = self.stamps[-1] - self.stamps[0]
            return (len(self.stamps) - 1) / span if span > 0 else None


def decode_last(raw: Any, type_name: str) -> str:
    """The last message as rostopic echo prints it, or a short note when it cannot be decoded."""
    from ninjemys.idl.loader import get_message_class, message_class_from_definition

    header = getattr(raw, "connection_header", {}) or {}
    definition = header.get("message_definition")
    try:
        if definition:
            cls = message_class_from_definition(type_name, definition, header.get("md5sum"))
        else:
            cls = get_message_class(type_name)
        text = str(cls.deserialize_from(bytes(raw.data)))
    except (NinjemysError, ValueError) as exc:
        return f"({len(raw.data)} bytes; cannot decode {type_name}: {exc})"
    return text if len(text) <= MESSAGE_LIMIT else text[:MESSAGE_LIMIT] + "\n..."


class TopicMonitor:
    """Watches topics on demand through a node made by ``node_factory`` (created at first use)."""

    def __init__(self, node_factory: Callable[[], Any]) -> None:
        self._node_factory = node_factory
        self._node: Any = None
        self._watches: dict[str, _Watch] = {}
        self._lock = threading.Lock()

    def node_names(self) -> frozenset[str]:
        """The monitor's own node (once created), for the graph to tag as debug."""
        node = self._node
        return frozenset({node.name}) if node is not None else frozenset()

    def info(self, topic: str, type_name: str) -> dict:
        """Rate (Hz or None), message count since watching started, and the last message as text."""
        self._expire()
        with self._lock:
            watch = self._watches.get(topic)
            if watch is None:
                if self._node is None:
                    self._node = self._node_factory()
                watch = _Watch(None)
                watch.subscriber = self._node.subscriber(
                    topic, None, watch.on_message, raw=True, queue_size=10
                )
                self._watches[topic] = watch
        watch.asked = time.monotonic()
        with watch.lock:
            last, count = watch.last, watch.count
        return {
            "rate": watch.rate(),
            "count": count,
            "last_message": decode_last(last, type_name) if last is not None else "",
        }

    def _expire(self) -> None:
        now = time.monotonic()
        with self._lock:
            idle = [t for t, w in self._watches.items() if now - w.asked > IDLE_TIMEOUT]
            for topic in idle:
                self._watches.pop(topic).subscriber.unregister()

    def close(self) -> None:
        with self._lock:
            watches, self._watches = list(self._watches.values()), {}
            node, self._node = self._node, None
        for watch in watches:
            watch.subscriber.unregister()
        if node is not None:
            node.shutdown("web tools closing")
