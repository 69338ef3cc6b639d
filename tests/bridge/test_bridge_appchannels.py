"""App channels: JSON an in-process app publishes on the gateway (a simulator's view), snapshot first."""

from __future__ import annotations

import json
import threading
import time
from typing import Any

from ninjemys.bridge.appchannels import AppChannel


def _collect(into: list[Any]) -> Any:
    return lambda d: into.append(json.loads(d.data))


def test_nothing_is_built_without_listeners_and_each_subscriber_gets_the_snapshot_first() -> None:
    lock = threading.Lock()
    state = {"n": 0}
    channel = AppChannel(7, "view:test", "ninjemys/Test", lambda: {"kind": "state", **state}, lock)
    assert channel.channel == {
        "id": 7,
        "topic": "view:test",
        "encoding": "json",
        "schemaName": "ninjemys/Test",
        "schema": "",
        "schemaEncoding": "jsonschema",
    }
    with lock:
        channel.publish({"kind": "update", "n": 1})  # nobody listens: dropped
    assert channel.listeners == 0
    first: list[Any] = []
    state["n"] = 1
    channel.add("a", _collect(first))
    with lock:
        channel.publish({"kind": "update", "n": 2})
    second: list[Any] = []
    channel.add("b", _collect(second))
    assert first == [{"kind": "state", "n": 1}, {"kind": "update", "n": 2}]
    assert second == [{"kind": "state", "n": 1}]
    channel.remove("a")
    with lock:
        channel.publish({"kind": "update", "n": 3})
    assert len(first) == 2 and second[-1] == {"kind": "update", "n": 3} and channel.listeners == 1


def test_a_subscriber_misses_no_update_published_while_it_joins() -> None:
    lock = threading.Lock()
    counter = {"n": 0}
    channel = AppChannel(1, "view:test", "ninjemys/Test", lambda: {"n": counter["n"]}, lock)
    stop = threading.Event()

    def publisher() -> None:
        while not stop.is_set():
            with lock:
                counter["n"] += 1
                channel.publish({"n": counter["n"]})

    thread = threading.Thread(target=publisher)
    thread.start()
    try:
        seen: list[Any] = []
        channel.add("late", _collect(seen))
        deadline = time.monotonic() + 10
        while len(seen) < 50 and time.monotonic() < deadline:
            time.sleep(0.001)
    finally:
        stop.set()
        thread.join()
    numbers = [m["n"] for m in seen]
    assert numbers == list(range(numbers[0], numbers[0] + len(numbers)))  # snapshot, then every update
