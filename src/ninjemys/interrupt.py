"""Blocking on the main thread without sleeping through Ctrl-C.

CPython runs a Python signal handler (rospy's shutdown, a tool's stop, ``KeyboardInterrupt``) only
on the main thread, and only when that thread runs bytecode. The kernel hands a process-directed
signal (Ctrl-C, ``kill``, roslaunch's SIGINT) to any thread that does not block it. When it lands on
one of the node's I/O or worker threads, a main thread parked in an untimed lock wait never wakes,
and the process ignores the signal for good (seen as a page tool, started by ``rosrun``, hanging
after Ctrl-C about once in 20 tries under load). Every wait on the main thread is therefore cut into
slices of at most :data:`SLICE` seconds; between slices CPython runs the pending handler. Real rospy
does the same (its ``spin`` and sim-time ``sleep`` wake every 0.3-0.5 s).
"""

from __future__ import annotations

import threading
import time

#: the longest the main thread blocks at once: the worst-case delay of a signal that landed elsewhere
SLICE = 0.2


def on_main_thread() -> bool:
    return threading.current_thread() is threading.main_thread()


def wait_slice(timeout: float | None) -> float | None:
    """``timeout`` for one blocking call: capped at :data:`SLICE` on the main thread, else unchanged.
    The caller loops and re-checks its condition, as it must anyway for spurious wake-ups."""
    if not on_main_thread():
        return timeout
    return SLICE if timeout is None else min(timeout, SLICE)


def wait_event(event: threading.Event, timeout: float | None = None) -> bool:
    """``event.wait(timeout)`` that lets signal handlers run when called on the main thread."""
    if not on_main_thread():
        return event.wait(timeout)
    deadline = None if timeout is None else time.monotonic() + timeout
    while True:
        left = SLICE if deadline is None else min(SLICE, deadline - time.monotonic())
        if left <= 0:
            return event.is_set()
        if event.wait(left):
            return True
