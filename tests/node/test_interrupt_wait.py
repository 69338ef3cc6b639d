"""``ninjemys.interrupt.wait_event`` on the main thread: an ``interrupt.Event`` is waited for with no
periodic wake-up (an idle node's main thread used to wake 5 times a second), and the wait still ends
at once for the event, for its timeout, and for a signal whichever thread the kernel handed it to.
(tests/node/test_signal_on_worker_thread.py does the same to whole processes with SIGINT.)"""

from __future__ import annotations

import signal
import sys
import threading
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from ninjemys import interrupt


class _Interrupted(Exception):
    pass


@pytest.fixture
def on_main() -> None:
    if not interrupt.on_main_thread():
        pytest.skip("wait_event's main-thread path needs the main thread")


@pytest.fixture
def usr1_raises() -> Iterator[None]:
    def handler(_sig: int, _frame: object) -> None:
        raise _Interrupted

    old = signal.signal(signal.SIGUSR1, handler)
    try:
        yield
    finally:
        signal.signal(signal.SIGUSR1, old)


def _signal_me_once_it_waits(event: interrupt.Event, delay: float = 0.0) -> None:
    """SIGUSR1 to this helper thread, not to the main one, once the main thread waits for ``event``
    (``delay``: when that cannot be seen, time for it to start waiting)."""
    deadline = time.monotonic() + 30
    while not event._main_waits and time.monotonic() < deadline and not delay:
        time.sleep(0.005)
    time.sleep(delay)
    signal.pthread_kill(threading.get_ident(), signal.SIGUSR1)


def _later(fn, delay: float = 0.1) -> threading.Thread:  # type: ignore[no-untyped-def]
    thread = threading.Timer(delay, fn)
    thread.start()
    return thread


def test_set_from_another_thread_ends_the_wait(on_main: None) -> None:
    event = interrupt.Event()
    _later(event.set).join(0)
    assert interrupt.wait_event(event, 30.0) is True
    assert interrupt.wait_event(event) is True  # already set: at once


def test_the_timeout_ends_the_wait(on_main: None) -> None:
    assert interrupt.wait_event(interrupt.Event(), 0.05) is False


@pytest.mark.skipif(not hasattr(signal, "pthread_kill"), reason="needs pthread_kill")
def test_a_signal_handed_to_another_thread_runs_its_handler_at_once(on_main: None, usr1_raises: None) -> None:
    """The kernel may hand a process-directed signal to any thread; CPython runs the handler only on
    the main thread. A main thread parked in a plain untimed wait would never run it."""

    event = interrupt.Event()  # never set: only the handler's exception can end this wait
    helper = threading.Thread(target=_signal_me_once_it_waits, args=(event,))
    helper.start()
    with pytest.raises(_Interrupted):
        interrupt.wait_event(event)
    helper.join()


@pytest.mark.skipif(not hasattr(signal, "pthread_kill"), reason="needs pthread_kill")
def test_with_the_wakeup_fd_taken_by_another_owner_it_waits_in_slices(
    on_main: None, usr1_raises: None
) -> None:
    import socket

    theirs_r, theirs_w = socket.socketpair()
    theirs_w.setblocking(False)
    previous = signal.set_wakeup_fd(theirs_w.fileno())
    try:
        event = interrupt.Event()
        _later(event.set).join(0)
        assert interrupt.wait_event(event, 30.0) is True
        assert signal.set_wakeup_fd(theirs_w.fileno()) == theirs_w.fileno()  # left to its owner
        event = interrupt.Event()
        helper = threading.Thread(target=_signal_me_once_it_waits, args=(event, 0.5))
        helper.start()
        with pytest.raises(_Interrupted):
            interrupt.wait_event(event)  # a slice ends, the handler runs
        helper.join()
    finally:
        signal.set_wakeup_fd(previous)
        theirs_r.close()
        theirs_w.close()


def _switches(tid: int) -> int:
    for line in Path(f"/proc/self/task/{tid}/status").read_text().splitlines():
        if line.startswith("voluntary_ctxt_switches:"):
            return int(line.split()[1])
    raise AssertionError("no voluntary_ctxt_switches")


@pytest.mark.skipif(sys.platform != "linux", reason="counts the main thread's wake-ups in /proc")
def test_the_main_thread_does_not_wake_while_it_waits(on_main: None) -> None:
    """Each wake-up of a blocked thread is one voluntary context switch: over 1.5 s of waiting a
    sliced wait takes 8 or more, this one 1-2 (going to sleep, and the set)."""
    tid = threading.main_thread().native_id
    assert tid is not None
    event = interrupt.Event()
    counts: list[int] = []

    def watch() -> None:
        time.sleep(0.2)  # the main thread is waiting by now (if not, it only waits less)
        counts.append(_switches(tid))
        time.sleep(1.5)
        counts.append(_switches(tid))
        event.set()

    watcher = threading.Thread(target=watch)
    watcher.start()
    assert interrupt.wait_event(event, 60.0)
    watcher.join()
    assert counts[1] - counts[0] <= 3, counts


@pytest.mark.skipif(sys.platform != "linux", reason="counts the main thread's wake-ups in /proc")
def test_a_wall_time_sleep_on_the_main_thread_does_not_wake_and_wake_still_ends_it(on_main: None) -> None:
    """rospy.sleep / Rate.sleep on the main thread (Clock's wall-time gate): one long sleep, no slices;
    Clock.wake() (a Timer's shutdown) still opens it at once."""
    from ninjemys.node.clock import Clock, Wake

    tid = threading.main_thread().native_id
    assert tid is not None
    clock = Clock()
    before = _switches(tid)
    assert clock.wait_for(1.5) == Wake.REACHED
    assert _switches(tid) - before <= 3
    stop = threading.Event()
    opener = threading.Thread(target=lambda: [time.sleep(0.2), stop.set(), clock.wake()])
    opener.start()
    assert clock.wait_for(60.0, cancelled=stop.is_set) == Wake.CANCELLED
    opener.join()


@pytest.mark.skipif(sys.platform != "linux", reason="counts the main thread's wake-ups in /proc")
def test_a_sim_time_sleep_on_the_main_thread_does_not_wake_until_its_time_comes(on_main: None) -> None:
    from ninjemys.node.clock import Clock, Wake

    tid = threading.main_thread().native_id
    assert tid is not None
    clock = Clock(sim=True)
    clock.set_time(100)
    counts: list[int] = []

    def drive() -> None:
        time.sleep(0.2)
        counts.append(_switches(tid))
        clock.set_time(100, 500_000_000)  # not yet: no wake-up
        time.sleep(1.5)
        counts.append(_switches(tid))
        clock.set_time(101)

    driver = threading.Thread(target=drive)
    driver.start()
    assert clock.wait_for(1.0) == Wake.REACHED
    driver.join()
    assert counts[1] - counts[0] <= 3, counts
    assert clock.now() == 101.0
