"""Channels an in-process app publishes on the gateway beside the ROS topics: the simulators' views.

A simulator's browser view needs data no ROS topic carries (turtlesim's pen trail, the PuzzleBot
world's outlines and trails), and real ROS has no such topics, so adding them to the graph would
change what ``rostopic list`` shows. An :class:`AppChannel` is a Foxglove channel that only the
gateway knows: JSON messages (Foxglove's ``json`` encoding), advertised to Foxglove clients like any
channel, never registered with the master. The page subscribes to it with the same client it uses
for topics (``lib/rosclient.js``), so the browser has one data path.

``snapshot`` (optional) gives the full state a new subscriber needs first; only that subscriber
gets it. With ``lock`` (the app's lock, held by the app around every ``publish``), the snapshot and
the registration happen under it, so a subscriber misses no update between the two. :attr:`AppChannel.listeners` tells the app whether anyone watches, so it can skip work.
"""

from __future__ import annotations

import json
import threading
import time
from collections.abc import Callable
from typing import Any

Sink = Callable[[Any], None]


class AppDelivery:
    """One JSON message as the Foxglove sinks take a ROS delivery (data, stamp, per-key encodings)."""

    __slots__ = ("topic", "data", "stamp_ns", "cache")

    def __init__(self, topic: str, data: bytes, stamp_ns: int) -> None:
        self.topic = topic
        self.data = data
        self.stamp_ns = stamp_ns
        self.cache: dict[Any, Any] = {}

    def encoded(self, key: Any, build: Callable[[AppDelivery], Any]) -> Any:
        try:
            return self.cache[key]
        except KeyError:
            value = self.cache[key] = build(self)
            return value


class AppChannel:
    """A gateway channel fed by ``publish`` from the app's own threads (see the module docstring)."""

    def __init__(
        self,
        channel_id: int,
        topic: str,
        schema_name: str,
        snapshot: Callable[[], Any] | None = None,
        lock: Any = None,
    ) -> None:
        self.id = channel_id
        self.topic = topic
        self.channel = {
            "id": channel_id,
            "topic": topic,
            "encoding": "json",
            "schemaName": schema_name,
            "schema": "",
            "schemaEncoding": "jsonschema",
        }
        self._snapshot = snapshot
        self._app_lock = lock
        self._sinks: dict[Any, Sink] = {}
        self._lock = threading.Lock()

    @property
    def listeners(self) -> int:
        """How many subscriptions are open (0: nobody looks; the app may skip building messages)."""
        return len(self._sinks)

    def publish(self, value: Any) -> None:
        """Send ``value`` (JSON-serializable) to every subscriber; nothing is built when none listens."""
        with self._lock:
            sinks = list(self._sinks.values())
        if not sinks:
            return
        delivery = AppDelivery(self.topic, json.dumps(value, separators=(",", ":")).encode(), time.time_ns())
        for sink in sinks:
            sink(delivery)

    def add(self, key: Any, sink: Sink) -> None:
        """Subscribe ``sink``; it gets the snapshot first (if the app gave one), then every publish."""
        if self._app_lock is None:
            self._add(key, sink)
            return
        with self._app_lock:
            self._add(key, sink)

    def _add(self, key: Any, sink: Sink) -> None:
        first = self._snapshot() if self._snapshot is not None else None
        if first is not None:
            sink(AppDelivery(self.topic, json.dumps(first, separators=(",", ":")).encode(), time.time_ns()))
        with self._lock:
            self._sinks[key] = sink

    def remove(self, key: Any) -> None:
        with self._lock:
            self._sinks.pop(key, None)
