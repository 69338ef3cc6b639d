"""One client's send queue: bounded memory, per-topic lanes, fair draining, counted drops.

ROS threads put topic data; the client's sender task on the event loop takes it when the socket
can take more. The rules (ros-foxglove-bridge#174, rosbridge_suite#212):

- replies, statuses and announcements (the *control* lane) are never dropped and always go first;
- each topic has its own lane holding at most ``queue_length`` messages: a new one pushes the
  oldest out;
- when the whole box is over its byte budget, the oldest message of the lane holding the most
  bytes goes, so a big topic pays for its own backlog and a small one is never starved;
- the sender takes one message per lane in turn (round robin), so a burst on one topic cannot
  delay the others by more than one message each.

Every drop is counted per topic (``dropped``), for the ``status`` reports.
"""

from __future__ import annotations

import threading
from collections import Counter, OrderedDict, deque
from collections.abc import Callable
from typing import Any


class CloseRequest:
    """Queued after a session's last words: the sender closes the connection when it gets here."""

    __slots__ = ("code", "reason")

    def __init__(self, code: int, reason: str) -> None:
        self.code = code
        self.reason = reason

    def __len__(self) -> int:
        return 0


Frame = str | bytes | bytearray | memoryview
#: one message, or several frames that must go together (rosbridge fragments of one message), or the
#: request to close the connection
Item = Frame | tuple[Frame, ...] | CloseRequest


def _size(item: Item) -> int:
    return sum(len(f) for f in item) if isinstance(item, tuple) else len(item)


class _Lane:
    __slots__ = ("items", "bytes", "limit")

    def __init__(self, limit: int) -> None:
        self.items: deque[Item] = deque()
        self.bytes = 0
        self.limit = limit


class Outbox:
    """A thread-safe, bounded, fair queue; ``wake`` is called (from any thread) when it becomes non-empty."""

    def __init__(self, max_bytes: int, wake: Callable[[], None]) -> None:
        self.max_bytes = max_bytes
        self._wake = wake
        self._lock = threading.Lock()
        self._control: deque[Item] = deque()
        self._control_bytes = 0
        self._lanes: OrderedDict[str, _Lane] = OrderedDict()
        self._lane_bytes = 0
        self._armed = False
        self.dropped: Counter[str] = Counter()

    @property
    def bytes(self) -> int:
        return self._lane_bytes + self._control_bytes

    def put_control(self, item: Item) -> None:
        with self._lock:
            self._control.append(item)
            self._control_bytes += _size(item)
            self._arm()

    def put(self, lane: str, item: Item, queue_length: int) -> None:
        """Queue topic data on ``lane``; drops the oldest of this lane past ``queue_length`` and the
        oldest of the largest lane while the box is over budget."""
        size = _size(item)
        with self._lock:
            entry = self._lanes.get(lane)
            if entry is None:
                entry = self._lanes[lane] = _Lane(max(1, queue_length))
            entry.limit = max(1, queue_length)
            entry.items.append(item)
            entry.bytes += size
            self._lane_bytes += size
            while len(entry.items) > entry.limit:
                self._drop_oldest(lane, entry)
            while self._lane_bytes + self._control_bytes > self.max_bytes:
                name, biggest = max(self._lanes.items(), key=lambda kv: kv[1].bytes)
                if not biggest.items or (name == lane and len(entry.items) == 1 and len(self._lanes) == 1):
                    break  # one message bigger than the budget: it is sent alone
                self._drop_oldest(name, biggest)
            self._arm()

    def _drop_oldest(self, name: str, lane: _Lane) -> None:
        old = lane.items.popleft()
        size = _size(old)
        lane.bytes -= size
        self._lane_bytes -= size
        self.dropped[name] += 1

    def _arm(self) -> None:
        if not self._armed:
            self._armed = True
            self._wake()

    def take(self) -> Item | None:
        """The next item to send (control first, then one per lane in turn), or None (and re-arm)."""
        with self._lock:
            if self._control:
                item = self._control.popleft()
                self._control_bytes -= _size(item)
                return item
            for _ in range(len(self._lanes)):
                name, lane = next(iter(self._lanes.items()))
                self._lanes.move_to_end(name)
                if lane.items:
                    item = lane.items.popleft()
                    size = _size(item)
                    lane.bytes -= size
                    self._lane_bytes -= size
                    return item
            self._armed = False
            return None

    def discard(self, lane: str) -> None:
        """Forget a lane (unsubscribe): its queued data is not sent."""
        with self._lock:
            entry = self._lanes.pop(lane, None)
            if entry is not None:
                self._lane_bytes -= entry.bytes


class Backlog:
    """Messages a client sent that its session has not handled yet. Past ``limit`` the connection
    stops reading (TCP then slows the client down) until half of them are done, so a client that
    sends faster than its ops run cannot grow the server's memory either."""

    def __init__(self, limit: int = 1000) -> None:
        self.limit = limit
        self._count = 0
        self._lock = threading.Lock()
        self._loop: Any = None
        self._open: Any = None

    def bind(self, loop: Any, event: Any) -> None:
        """``event`` (an asyncio.Event of ``loop``) is set while the connection may read."""
        self._loop, self._open = loop, event
        event.set()

    def add(self) -> None:
        with self._lock:
            self._count += 1
            if self._count == self.limit and self._loop is not None:
                self._loop.call_soon_threadsafe(self._open.clear)

    def done(self) -> None:
        with self._lock:
            self._count -= 1
            if self._count == self.limit // 2 and self._loop is not None:
                self._loop.call_soon_threadsafe(self._open.set)

    async def wait(self) -> None:
        if self._open is not None:
            await self._open.wait()
