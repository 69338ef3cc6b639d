"""Sleeping in ROS time: ``sleep``, ``Rate`` and ``Timer`` over a :class:`~ninjemys.node.clock.Clock`.

Semantics follow rospy, with one deliberate improvement for simulated time:

* ``sleep(d)`` returns after ``d`` seconds of ROS time, raises :class:`~ninjemys.errors.ShutdownError`
  as soon as the node shuts down, and raises :class:`TimeMovedBackwardsError` if simulated time jumps
  backwards meanwhile (as rospy's ROSTimeMovedBackwardsException: a plain sleep has no sensible
  target after a jump, so the caller must decide).
* ``Rate.sleep()`` keeps a fixed period. When simulated time jumps backwards (``rosbag play --loop
  --clock``), it **resets** to the new time and carries on instead of raising — in rospy that exception
  killed the loop of every node unless it passed ``reset=True`` (ros_comm #485, #1083). Passing
  ``reset=False`` explicitly restores rospy's raising behaviour.
* ``Timer`` runs its callback on its own thread with a :class:`TimerEvent`; a backwards jump
  re-anchors its schedule instead of ending the thread (again rospy's default killed it).

Nothing here polls: waits block on the clock's condition variable until time advances, the node shuts
down, or the timer is stopped.
"""

from __future__ import annotations

import threading
from collections.abc import Callable

from ninjemys.errors import NinjemysError, ShutdownError
from ninjemys.node.clock import Clock, Wake

TYPE_CHECKING = False  # importing typing costs ~7 ms of every node's start-up; checkers set it
if TYPE_CHECKING:
    from typing import Any


class TimeMovedBackwardsError(NinjemysError):
    """ROS time jumped backwards during a sleep (rospy: ROSTimeMovedBackwardsException)."""

    def __init__(self, time_before: float, time_after: float) -> None:
        self.time_before = time_before
        self.time_after = time_after
        super().__init__(
            f"ROS time moved backwards from {time_before:.9f} to {time_after:.9f} during a sleep"
        )


def _seconds(duration: Any) -> float:
    """A float of seconds from a number or a Duration-like object (``to_sec()``)."""
    to_sec = getattr(duration, "to_sec", None)
    return float(to_sec()) if to_sec is not None else float(duration)


def sleep(clock: Clock, duration: Any) -> None:
    """Sleep ``duration`` seconds (or a Duration) of ROS time; a non-positive duration returns at once.

    In simulated time before the first /clock message, the duration counts from that first message
    (rospy semantics: a node started before ``rosbag play --clock`` sleeps the full duration).
    """
    seconds = _seconds(duration)
    if clock.is_shutdown:
        raise ShutdownError("ROS shutdown request")
    if seconds <= 0:
        return
    if clock.is_sim and clock.now_ns() == 0:
        # simulated time has not started yet: count the duration from the first /clock, as rospy does
        if clock.wait_until(1e-9) is Wake.SHUTDOWN:
            raise ShutdownError("ROS shutdown request")
    start = clock.now()
    wake = clock.wait_until(start + seconds)
    if wake is Wake.SHUTDOWN:
        raise ShutdownError("ROS shutdown request")
    if wake is Wake.MOVED_BACKWARDS:
        raise TimeMovedBackwardsError(start, clock.now())


class RateError(NinjemysError, ValueError, ZeroDivisionError):
    """A Rate with no usable frequency. Also a ZeroDivisionError, because ``rospy.Rate(0)`` raises
    one (it divides by the frequency), and code written for rospy may catch that."""


class Rate:
    """Loop at a fixed frequency: call :meth:`sleep` once per iteration.

    Args:
        hz: loop frequency.
        clock: the ROS clock to follow.
        reset: True (default) re-anchors the schedule when simulated time jumps backwards; False raises
            TimeMovedBackwardsError as rospy did by default.
    """

    def __init__(self, hz: float, clock: Clock, reset: bool = True) -> None:
        if hz <= 0:
            raise RateError(f"Rate: frequency must be positive, got {hz}")
        self.period = 1.0 / hz
        self._clock = clock
        self._reset = reset
        self.last_time = clock.now()

    def remaining(self) -> float:
        """Seconds left until the next deadline (negative when the loop is late)."""
        now = self._clock.now()
        if now < self.last_time:
            self.last_time = now
        return self.last_time + self.period - now

    def sleep(self) -> None:
        """Sleep until the next period boundary; raises ShutdownError when the node shuts down."""
        clock = self._clock
        if clock.is_sim and self.last_time == 0.0 and clock.now_ns() == 0:
            # made before simulated time started: the first period counts from the first /clock (rospy)
            if clock.wait_until(1e-9) is Wake.SHUTDOWN:
                raise ShutdownError("ROS shutdown request")
            self.last_time = clock.now()
        now = clock.now()
        if now < self.last_time:
            # time already went backwards between two calls
            if not self._reset:
                raise TimeMovedBackwardsError(self.last_time, now)
            self.last_time = now
        target = self.last_time + self.period
        wake = clock.wait_until(target) if target > now else Wake.REACHED
        if clock.is_shutdown or wake is Wake.SHUTDOWN:
            raise ShutdownError("ROS shutdown request")
        if wake is Wake.MOVED_BACKWARDS:
            if not self._reset:
                raise TimeMovedBackwardsError(target, clock.now())
            self.last_time = clock.now()
            return
        self.last_time = target
        if now - self.last_time > self.period * 2:
            # far behind (a long stall): restart from now instead of bursting to catch up
            self.last_time = now


class TimerEvent:
    """What a Timer callback is told (rospy.timer.TimerEvent fields, times in ROS seconds or Time).

    A plain slotted class rather than a dataclass: it is built on every tick and imported by every node.
    """

    __slots__ = ("last_expected", "last_real", "current_expected", "current_real", "last_duration")

    def __init__(
        self,
        last_expected: Any,
        last_real: Any,
        current_expected: Any,
        current_real: Any,
        last_duration: float | None,
    ) -> None:
        self.last_expected = last_expected
        self.last_real = last_real
        self.current_expected = current_expected
        self.current_real = current_real
        self.last_duration = last_duration

    def __repr__(self) -> str:
        fields = ", ".join(f"{name}={getattr(self, name)!r}" for name in self.__slots__)
        return f"TimerEvent({fields})"


class Timer:
    """Call ``callback(TimerEvent)`` every ``period`` seconds of ROS time on a dedicated thread.

    Args:
        clock: the ROS clock.
        period: seconds (float) or a Duration.
        callback: the user function; an exception in it is reported through ``on_error`` and the timer
            keeps running (rospy would end the thread).
        oneshot: fire once.
        make_time: converts float seconds into the time type handed to the callback (rospy.Time).
    """

    def __init__(
        self,
        clock: Clock,
        period: Any,
        callback: Callable[[TimerEvent], Any],
        oneshot: bool = False,
        make_time: Callable[[float], Any] = float,
        on_error: Callable[[BaseException], None] | None = None,
        name: str = "ninjemys-timer",
    ) -> None:
        self._period = _seconds(period)
        if self._period <= 0 and not oneshot:
            raise ValueError(f"Timer: period must be positive, got {self._period}")
        self._clock = clock
        self._callback = callback
        self._oneshot = oneshot
        self._make_time = make_time
        self._on_error = on_error
        self._stopped = False
        self._thread = threading.Thread(target=self._run, name=name, daemon=True)
        self._thread.start()

    def shutdown(self) -> None:
        """Stop the timer; a callback already running finishes, no further one starts."""
        self._stopped = True
        self._clock.wake()

    def join(self, timeout: float | None = None) -> None:
        if self._thread is not threading.current_thread():
            self._thread.join(timeout)

    def is_alive(self) -> bool:
        return self._thread.is_alive()

    def _cancelled(self) -> bool:
        return self._stopped

    def _run(self) -> None:
        clock = self._clock
        mk = self._make_time
        last_expected = last_real = None
        last_duration: float | None = None
        if clock.is_sim and clock.now_ns() == 0:
            # simulated time has not started: the first period counts from the first /clock (rospy)
            if clock.wait_until(1e-9, self._cancelled) in (Wake.SHUTDOWN, Wake.CANCELLED):
                return
        expected = clock.now() + self._period
        while True:
            wake = clock.wait_until(expected, self._cancelled)
            if wake in (Wake.SHUTDOWN, Wake.CANCELLED):
                return
            if wake is Wake.MOVED_BACKWARDS:
                expected = clock.now() + self._period
                last_expected = last_real = None
                continue
            real = clock.now()
            event = TimerEvent(
                None if last_expected is None else mk(last_expected),
                None if last_real is None else mk(last_real),
                mk(expected),
                mk(real),
                last_duration,
            )
            started = clock.now()
            try:
                self._callback(event)
            except Exception as exc:
                if self._on_error is not None:
                    self._on_error(exc)
            last_duration = clock.now() - started
            if self._oneshot or self._stopped:
                return
            last_expected, last_real = expected, real
            expected += self._period
            if clock.now() > expected + self._period:
                # the callback overran by more than a period: skip missed ticks instead of bursting
                expected = clock.now() + self._period
