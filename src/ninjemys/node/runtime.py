"""The process's one I/O loop, on its own thread, and the only thread hand-offs.

Every socket of every Node in the process (TCPROS server and streams, the slave XML-RPC server) is
served by this loop. The loop never runs user code and never blocks. User threads reach it only
through :meth:`Runtime.call_soon` (fire and forget) and :meth:`Runtime.run` (wait for a coroutine's
result); work leaves it only through the subscription queues and the helper threads started with
:meth:`Runtime.start_thread`.

The loop is :class:`ninjemys.net.loop.Loop`, not asyncio's: a node needs a small part of asyncio
and ``import asyncio`` alone would cost more than the rest of ``import rospy`` (see docs/node.md).

The loop is reference counted by the nodes that use it: it starts with the first node and stops
(its thread joined) when the last one shuts down, so a finished program leaves no thread behind.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable, Coroutine

from ninjemys.errors import ShutdownError, TimeoutError_
from ninjemys.net.loop import CancelledError, Loop, ThreadFuture

_log = logging.getLogger(__name__)
TYPE_CHECKING = False  # importing typing costs ~7 ms of every node's start-up; checkers set it
if TYPE_CHECKING:
    from typing import Any, TypeVar

    T = TypeVar("T")


class Runtime:
    """An event loop running on a dedicated daemon thread."""

    def __init__(self) -> None:
        self.loop = Loop()
        self._ready = threading.Event()
        self.thread = threading.Thread(target=self._main, name="ninjemys-io", daemon=True)
        self.thread.start()
        self._ready.wait()

    def _main(self) -> None:
        self.loop.call_soon(self._ready.set)
        try:
            self.loop.run_forever()
        finally:
            self.loop.shutdown_tasks(grace=1.0)
            self.loop.close()

    @property
    def on_loop(self) -> bool:
        """True when called from the I/O thread itself."""
        return threading.current_thread() is self.thread

    @property
    def alive(self) -> bool:
        return self.thread.is_alive() and not self.loop.is_closed()

    def call_soon(self, fn: Callable[..., Any], *args: Any) -> None:
        """Run ``fn(*args)`` on the loop as soon as possible (from any thread; never waits)."""
        if self.on_loop:
            fn(*args)
            return
        try:
            self.loop.call_soon_threadsafe(fn, *args)
        except RuntimeError:
            _log.debug("I/O loop already closed; dropped %r", fn)

    def defer(self, fn: Callable[..., Any], *args: Any) -> None:
        """Run ``fn(*args)`` at the loop's next turn, even when called on the loop itself: for a call
        that takes a lock its caller may hold (a connection that fails while its publication's lock
        is held reports its end this way; run inline, the report waited for that lock on the I/O
        thread, and every later operation of the process waited for the I/O thread)."""
        try:
            self.loop.call_soon_threadsafe(fn, *args)
        except RuntimeError:
            _log.debug("I/O loop already closed; dropped %r", fn)

    def spawn(self, coro: Coroutine[Any, Any, T]) -> ThreadFuture:
        """Schedule ``coro`` on the loop and return a future usable from any thread."""
        try:
            return self.loop.run_coroutine_threadsafe(coro)
        except RuntimeError:
            raise ShutdownError("the ninjemys I/O loop has stopped") from None

    def run(self, coro: Coroutine[Any, Any, T], timeout: float | None = None) -> T:
        """Run ``coro`` on the loop and wait for its result from a user thread."""
        if self.on_loop:
            coro.close()
            raise RuntimeError("Runtime.run() called on the I/O thread: it would deadlock")
        future = self.spawn(coro)
        try:
            return future.result(timeout)
        except TimeoutError:
            if future.done():
                raise  # the coroutine's own deadline
            future.cancel()
            raise TimeoutError_(f"I/O operation did not finish within {timeout} s") from None
        except CancelledError:
            raise ShutdownError("the ninjemys I/O loop stopped before the operation finished") from None

    def start_thread(self, target: Callable[[], None], name: str) -> threading.Thread:
        """Start a daemon helper thread (subscription workers, service connections)."""
        thread = threading.Thread(target=target, name=name, daemon=True)
        thread.start()
        return thread

    def stop(self) -> None:
        """Stop the loop and join its thread (no-op from the loop thread itself, which just stops)."""
        try:
            self.loop.call_soon_threadsafe(self.loop.stop)
        except RuntimeError:
            return
        if not self.on_loop:
            self.thread.join(5.0)


_lock = threading.Lock()
_runtime: Runtime | None = None
_users = 0


def acquire() -> Runtime:
    """The process's runtime, started on first use; pair every call with :func:`release`."""
    global _runtime, _users
    with _lock:
        if _runtime is None or not _runtime.alive:
            _runtime = Runtime()
        _users += 1
        return _runtime


def release() -> None:
    """Drop one user; the last one stops the loop and joins its thread."""
    global _runtime, _users
    with _lock:
        _users = max(0, _users - 1)
        if _users or _runtime is None:
            return
        runtime, _runtime = _runtime, None
    runtime.stop()


def current() -> Runtime | None:
    """The running runtime, if any node holds it."""
    return _runtime
