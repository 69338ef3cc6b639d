"""Fan-out of live updates to every open Server-Sent Events stream.

Producers may live on any thread (a subscriber callback, the turtlesim timer); they call
:meth:`Hub.publish`, which hands the event to the web loop. Each browser gets its own bounded queue: a
slow tab loses old events (and is told to resynchronise) instead of growing memory or blocking the
producer.
"""

from __future__ import annotations

import asyncio
from collections.abc import Callable

from ninjemys.serve.http import EventStream

#: Events a single slow browser may lag behind before it is resynchronised.
QUEUE_LIMIT = 1000


class Hub:
    """One topic of live events (e.g. "graph" or "turtlesim") with any number of browser streams."""

    def __init__(self, loop: asyncio.AbstractEventLoop) -> None:
        self._loop = loop
        self._queues: set[asyncio.Queue[tuple[str, object] | None]] = set()

    def open(self, initial: list[tuple[str, object]] | None = None) -> EventStream:
        """A new stream for one browser, primed with ``initial`` events (call on the web loop)."""
        queue: asyncio.Queue[tuple[str, object] | None] = asyncio.Queue(QUEUE_LIMIT)
        for item in initial or []:
            queue.put_nowait(item)
        self._queues.add(queue)
        return EventStream(queue, lambda: self._queues.discard(queue))

    @property
    def listeners(self) -> int:
        return len(self._queues)

    def publish(self, event: str, data: object, resync: Callable[[], object] | None = None) -> None:
        """Send to every stream; thread-safe. ``resync`` builds a full state for streams that overflowed."""
        if self._loop.is_closed():
            return
        try:
            self._loop.call_soon_threadsafe(self._deliver, event, data, resync)
        except RuntimeError:  # loop closed between the check and the call
            return

    def _deliver(self, event: str, data: object, resync: Callable[[], object] | None) -> None:
        for queue in list(self._queues):
            if queue.full():
                while not queue.empty():
                    queue.get_nowait()
                if resync is not None:
                    queue.put_nowait(("state", resync()))
                continue
            queue.put_nowait((event, data))

    def close(self) -> None:
        """End every stream (thread-safe)."""
        if not self._loop.is_closed():
            self._loop.call_soon_threadsafe(self._end_all)

    def _end_all(self) -> None:
        for queue in list(self._queues):
            while queue.full():
                queue.get_nowait()
            queue.put_nowait(None)
