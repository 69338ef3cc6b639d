"""Asynchronous notifications from the master to nodes: publisherUpdate, paramUpdate, shutdown.

rosmaster sends these from three worker threads that block in ``recv`` on whatever node they call, so
three dead or hostile nodes freeze topic discovery for everyone (ros/ros_comm#1555). Here:

* every node API has its own queue and its own sender task, so a node only ever delays itself;
* each call has a deadline (``timeout``); a node that misses it costs a log line;
* calls to one node stay in order, and a pending update is *replaced* by a newer one for the same
  topic or parameter (only the latest publisher list matters), so a stuck node's queue is bounded by
  the number of distinct topics/keys, not by the number of changes;
* at most ``max_concurrent`` connections are open at once, so a burst of thousands of nodes cannot
  exhaust file descriptors.

A node that answers ``paramUpdate`` with code -1 is unsubscribed from that key, as in ROS 1.

A node whose API *refuses* connections is not running: it is marked dead and further calls to it are
dropped (one log line, no sockets) until it registers again (:meth:`Notifier.revive`), which is what a
restarted node does first. A graph full of crashed nodes thus costs the master nothing.
"""

from __future__ import annotations

import asyncio
import logging
from collections.abc import Callable
from typing import Any

from ninjemys.net import xmlrpc_client

log = logging.getLogger(__name__)

MASTER_CALLER_ID = "/master"


class Notifier:
    """Per-node ordered, coalescing, deadline-bounded XML-RPC calls from the master."""

    def __init__(
        self,
        timeout: float = 10.0,
        max_concurrent: int = 64,
        on_param_rejected: Callable[[str, str], None] | None = None,
    ) -> None:
        self.timeout = timeout
        self._limit = asyncio.Semaphore(max_concurrent)
        self._queues: dict[str, dict[tuple[str, str], tuple[str, tuple[Any, ...]]]] = {}
        self._tasks: dict[str, asyncio.Task[None]] = {}
        self._on_param_rejected = on_param_rejected
        self._closed = False
        self._dead: set[str] = set()

    # ------------------------------------------------------------------------------------ API

    def publisher_update(self, api: str, topic: str, publishers: list[str]) -> None:
        self._enqueue(api, ("topic", topic), "publisherUpdate", (MASTER_CALLER_ID, topic, publishers))

    def param_update(self, api: str, key: str, value: Any) -> None:
        self._enqueue(api, ("param", key), "paramUpdate", (MASTER_CALLER_ID, key, value))

    def shutdown_node(self, api: str, message: str) -> None:
        self._enqueue(api, ("shutdown", ""), "shutdown", (MASTER_CALLER_ID, message))

    def revive(self, api: str) -> None:
        """``api`` registered something: it is alive again (cheap; called on every registration)."""
        if self._dead:
            self._dead.discard(api)

    def is_dead(self, api: str) -> bool:
        return api in self._dead

    def pending(self) -> int:
        """Calls queued or in flight (for tests and diagnostics)."""
        return sum(len(q) for q in self._queues.values()) + len(self._tasks)

    async def drain(self, timeout: float | None = None) -> None:
        """Wait until every queued call has been attempted."""
        async with asyncio.timeout(timeout):
            while self._tasks:
                await asyncio.gather(*list(self._tasks.values()), return_exceptions=True)

    def close(self) -> None:
        """Drop everything queued and cancel calls in flight."""
        self._closed = True
        self._queues.clear()
        for task in self._tasks.values():
            task.cancel()
        self._tasks.clear()

    # ------------------------------------------------------------------------------- internals

    def _enqueue(self, api: str, slot: tuple[str, str], method: str, params: tuple[Any, ...]) -> None:
        if self._closed or api in self._dead:
            return
        queue = self._queues.setdefault(api, {})
        queue[slot] = (method, params)  # a newer update for the same slot replaces the pending one
        if api not in self._tasks:
            self._tasks[api] = asyncio.get_running_loop().create_task(self._run(api))

    async def _run(self, api: str) -> None:
        try:
            while True:
                queue = self._queues.get(api)
                if not queue:
                    break
                slot = next(iter(queue))
                method, params = queue.pop(slot)
                await self._send(api, method, params)
        finally:
            if not self._queues.get(api):
                self._queues.pop(api, None)
            self._tasks.pop(api, None)
            if self._queues.get(api) and not self._closed:  # enqueued while we were finishing
                self._tasks[api] = asyncio.get_running_loop().create_task(self._run(api))

    async def _send(self, api: str, method: str, params: tuple[Any, ...]) -> None:
        async with self._limit:
            try:
                result = await xmlrpc_client.call(api, method, params, timeout=self.timeout)
            except asyncio.CancelledError:
                raise
            except ConnectionRefusedError:
                log.info(
                    "%s%s to %s: connection refused; node considered dead until it registers again",
                    method,
                    params[1:2],
                    api,
                )
                self._dead.add(api)
                self._queues.pop(api, None)
                return
            except Exception as exc:
                log.info("%s%s to %s failed: %s", method, params[1:2], api, exc)
                return
        if method == "paramUpdate" and self._on_param_rejected is not None:
            if isinstance(result, list) and result and result[0] == -1:
                self._on_param_rejected(api, params[1])
