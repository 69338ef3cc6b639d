"""A node stand-in for the actionlib cores: endpoints that record, a parameter dict, a log that keeps lines.

The cores only use the node's public API (publisher, subscriber, params, names, shutdown hooks), so
the state machines can be driven message by message, deterministically, without a master.
"""

from __future__ import annotations

import threading
from typing import Any


class FakePublisher:
    def __init__(self, topic: str, msg_class: Any, latch: bool) -> None:
        self.topic = topic
        self.msg_class = msg_class
        self.latch = latch
        self.sent: list[Any] = []
        self.cond = threading.Condition()
        self.subscribers: set[str] = set()
        self.closed = False

    def publish(self, msg: Any) -> None:
        with self.cond:
            # keep a decoded copy: the server reuses nothing, but a copy proves the message serializes
            self.sent.append(type(msg).deserialize_from(msg.serialize_to_bytes()))
            self.cond.notify_all()

    def wait_count(self, n: int, timeout: float = 5.0) -> list[Any]:
        with self.cond:
            assert self.cond.wait_for(lambda: len(self.sent) >= n, timeout), (
                f"{self.topic}: {len(self.sent)} < {n}"
            )
            return list(self.sent)

    def subscriber_ids(self) -> frozenset[str]:
        return frozenset(self.subscribers)

    def unregister(self) -> None:
        self.closed = True


class FakeSubscriber:
    def __init__(self, topic: str, msg_class: Any, callback: Any, raw: bool) -> None:
        self.topic = topic
        self.msg_class = msg_class
        self.callback = callback
        self.raw = raw
        self.publishers: set[str] = set()
        self.closed = False

    def publisher_ids(self) -> frozenset[str]:
        return frozenset(self.publishers)

    def deliver(self, msg: Any, callerid: str = "/peer") -> None:
        if self.raw:
            from ninjemys.node.subscriber import RawMessage

            self.callback(RawMessage(msg.serialize_to_bytes(), {"callerid": callerid}))
        else:
            self.callback(msg)

    def unregister(self) -> None:
        self.closed = True


class ListLog:
    def __init__(self) -> None:
        self.lines: list[tuple[str, str]] = []

    def _add(self, level: str, msg: Any, *args: Any) -> None:
        self.lines.append((level, str(msg) % args if args else str(msg)))

    def debug(self, msg: Any, *args: Any) -> None:
        self._add("debug", msg, *args)

    def info(self, msg: Any, *args: Any) -> None:
        self._add("info", msg, *args)

    def warn(self, msg: Any, *args: Any) -> None:
        self._add("warn", msg, *args)

    def error(self, msg: Any, *args: Any) -> None:
        self._add("error", msg, *args)

    def at(self, *levels: str) -> list[str]:
        return [text for level, text in self.lines if level in levels]


class FakeNode:
    def __init__(self, name: str = "/fake", params: dict[str, Any] | None = None) -> None:
        self.name = name
        self.params = dict(params or {})
        self.pubs: dict[str, FakePublisher] = {}
        self.subs: dict[str, FakeSubscriber] = {}
        self.hooks: list[Any] = []
        self.is_shutdown = False

    def resolve_name(self, name: str) -> str:
        return name if name.startswith("/") else "/" + name

    def publisher(
        self, topic: str, msg_class: Any, queue_size: Any = 10, latch: bool = False
    ) -> FakePublisher:
        pub = FakePublisher(topic, msg_class, latch)
        self.pubs[topic] = pub
        return pub

    def subscriber(
        self, topic: str, msg_class: Any, callback: Any, queue_size: Any = None, raw: bool = False
    ) -> FakeSubscriber:
        sub = FakeSubscriber(topic, msg_class, callback, raw)
        self.subs[topic] = sub
        return sub

    def get_param(self, key: str, default: Any = None) -> Any:
        return self.params.get(self.resolve_name(key), default)

    def has_param(self, key: str) -> bool:
        return self.resolve_name(key) in self.params

    def search_param(self, key: str) -> str | None:
        name = self.resolve_name(key)
        return name if name in self.params else None

    def on_shutdown(self, fn: Any) -> None:
        self.hooks.append(fn)

    def shutdown(self) -> None:
        self.is_shutdown = True
        for hook in self.hooks:
            hook()
