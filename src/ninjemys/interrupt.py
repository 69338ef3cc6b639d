"""Blocking on the main thread without sleeping through Ctrl-C, and without waking up to check.

CPython runs a Python signal handler (rospy's shutdown, a tool's stop, ``KeyboardInterrupt``) only
on the main thread, and only when that thread runs bytecode. The kernel hands a process-directed
signal (Ctrl-C, ``kill``, roslaunch's SIGINT) to any thread that does not block it. When it lands on
one of the node's I/O or worker threads, a main thread parked in an untimed lock wait never wakes,
and the process ignores the signal for good (seen as a page tool, started by ``rosrun``, hanging
after Ctrl-C about once in 20 tries under load).

Two ways out, best first:

- :func:`wait_event` on an :class:`Event` (``Node.spin``, ``rospy.spin``, a page tool serving): the
  main thread waits in ``poll()`` on one socket that two things write to: ``Event.set()``, and
  CPython's own C-level signal handler, through :func:`signal.set_wakeup_fd`, on whichever thread the
  signal landed. So the wait ends at once for either, and otherwise never wakes (an idle node's main
  thread used to wake 5 times a second). A signal that lands on the main thread interrupts ``poll()``
  itself (EINTR: the handler runs there). The wake-up fd is the process's one slot: it is taken only
  while nobody else holds it (an asyncio loop that handles signals does); then we fall back to slices.
- Everything else (a ``threading.Event`` of someone else, a condition wait) is cut into slices of at
  most :data:`SLICE` seconds on the main thread; between slices CPython runs the pending handler. Real
  rospy does the same (its ``spin`` and sim-time ``sleep`` wake every 0.3-0.5 s).
"""

from __future__ import annotations

import os
import select
import signal
import socket
import threading
import time

#: the longest the main thread blocks at once where it cannot wait on the wake-up socket: the
#: worst-case delay of a signal that landed on another thread
SLICE = 0.2


def on_main_thread() -> bool:
    return threading.current_thread() is threading.main_thread()


def wait_slice(timeout: float | None) -> float | None:
    """``timeout`` for one blocking call: capped at :data:`SLICE` on the main thread, else unchanged.
    The caller loops and re-checks its condition, as it must anyway for spurious wake-ups."""
    if not on_main_thread():
        return timeout
    return SLICE if timeout is None else min(timeout, SLICE)


class Event(threading.Event):
    """A ``threading.Event`` that :func:`wait_event` can wait for on the main thread with no periodic
    wake-up: ``set()`` also writes to the main thread's wake-up socket while it waits for this one."""

    def __init__(self) -> None:
        super().__init__()
        self._main_waits = False  # the main thread is in wait_event on this event (read by set())

    def set(self) -> None:
        super().set()
        if self._main_waits:
            _waker.wake()


class _Waker:
    """The main thread's wake-up socket pair, also installed as the process's signal wake-up fd."""

    def __init__(self) -> None:
        self._r: socket.socket | None = None
        self._w: socket.socket | None = None

    def wake(self) -> None:
        w = self._w
        if w is not None:
            try:
                w.send(b"\0")
            except OSError:  # full (the waiter drains it anyway) or closed
                pass

    def claim(self) -> socket.socket | None:
        """On the main thread: the read end, with the signal wake-up fd pointing at the write end;
        None when another owner holds the wake-up fd (then the caller waits in slices)."""
        if self._r is None:
            if hasattr(os, "register_at_fork"):
                os.register_at_fork(after_in_child=self._forget)
            r, w = socket.socketpair()
            r.setblocking(False)
            w.setblocking(False)
            self._r, self._w = r, w
        assert self._w is not None
        mine = self._w.fileno()
        try:
            # kept installed between waits: a signal that lands while the main thread runs code
            # between two waits leaves its byte, and the next wait returns at once to run the handler
            old = signal.set_wakeup_fd(mine, warn_on_full_buffer=False)
        except ValueError:  # not the main thread of the main interpreter
            return None
        if old not in (-1, mine):
            signal.set_wakeup_fd(old)  # someone else's (an asyncio loop's): leave it to them
            return None
        return self._r

    def _forget(self) -> None:
        """In a forked child: drop the parent's pair (and its wake-up fd, if it is ours); the child
        makes its own on its first wait."""
        r, w, self._r, self._w = self._r, self._w, None, None
        if w is None or r is None:
            return
        try:
            old = signal.set_wakeup_fd(-1)
            if old != w.fileno():
                signal.set_wakeup_fd(old)  # not ours: put it back
        except ValueError:
            pass
        r.close()
        w.close()

    def drain(self) -> None:
        r = self._r
        if r is None:
            return
        try:
            while r.recv(4096):
                pass
        except OSError:  # drained (BlockingIOError)
            pass


_waker = _Waker()


def _wait_readable(sock: socket.socket, timeout: float | None) -> None:
    """Block until ``sock`` is readable or ``timeout`` passes (poll where there is one: no fd limit)."""
    if hasattr(select, "poll"):
        poller = select.poll()
        poller.register(sock.fileno(), select.POLLIN)
        poller.poll(None if timeout is None else max(0, int(timeout * 1000) + 1))
    else:  # Windows
        select.select([sock], [], [], timeout)


def wait_event(event: threading.Event, timeout: float | None = None) -> bool:
    """``event.wait(timeout)`` that lets signal handlers run when called on the main thread: with no
    periodic wake-up for an :class:`Event`, in slices of :data:`SLICE` for any other event."""
    if not on_main_thread():
        return event.wait(timeout)
    deadline = None if timeout is None else time.monotonic() + timeout
    sock = _waker.claim() if isinstance(event, Event) else None
    if sock is None:
        while True:
            left = SLICE if deadline is None else min(SLICE, deadline - time.monotonic())
            if left <= 0:
                return event.is_set()
            if event.wait(left):
                return True
    assert isinstance(event, Event)
    event._main_waits = True  # before the check: a set() after it writes to the socket
    try:
        while not event.is_set():
            until: float | None = None if deadline is None else deadline - time.monotonic()
            if until is not None and until <= 0:
                return False
            # woken by set(), a signal on any thread (the handler runs once this returns to
            # bytecode: KeyboardInterrupt propagates, rospy's handler sets the event), or the time
            _wait_readable(sock, until)
            _waker.drain()
        return True
    finally:
        event._main_waits = False
