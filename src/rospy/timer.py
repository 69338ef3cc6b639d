"""rospy.Rate, rospy.sleep, rospy.Timer and rospy.TimerEvent over the process's ROS clock.

Thin adapters of :mod:`ninjemys.node.timers`; they convert core errors into rospy's exceptions.
Improvement over rospy: ``Rate`` and ``Timer`` re-anchor when simulated time jumps backwards instead
of dying with ROSTimeMovedBackwardsException (pass ``Rate(hz, reset=False)`` for the old behaviour).
"""

from __future__ import annotations

from collections.abc import Callable

from ninjemys.node import timers as _timers
from ninjemys.rostime import Duration, Time
from rospy.core import _process, is_shutdown
from rospy.exceptions import ROSInterruptException, mapped

TYPE_CHECKING = False  # importing typing costs ~7 ms of every node's start-up; checkers set it
if TYPE_CHECKING:
    from typing import Any

__all__ = ["Rate", "sleep", "Timer", "TimerEvent"]

TimerEvent = _timers.TimerEvent


def sleep(duration: float | Duration) -> None:
    """Sleep ``duration`` seconds of ROS time; ROSInterruptException if the node shuts down meanwhile."""
    with mapped():
        _timers.sleep(_process.clock, duration)


class Rate:
    """Loop at ``hz``: call ``sleep()`` once per iteration (``rate.sleep()`` in the seeds' talker)."""

    def __init__(self, hz: float, reset: bool = True) -> None:
        # rospy.Rate(0) raises ZeroDivisionError (the core's RateError is one); a negative rate is
        # accepted by rospy and never waits (its period is negative), so it is accepted here too.
        self._rate = None if hz < 0 else _timers.Rate(hz, _process.clock, reset=reset)
        self.sleep_dur = Duration.from_sec(1.0 / hz)
        self._created = _process.clock.now()

    @property
    def last_time(self) -> Time:
        return Time.from_sec(self._created if self._rate is None else self._rate.last_time)

    def remaining(self) -> Duration:
        """Time left until the next deadline."""
        if self._rate is None:
            return self.sleep_dur
        return Duration.from_sec(self._rate.remaining())

    def sleep(self) -> None:
        """Sleep until the next period; ROSInterruptException on shutdown."""
        if self._rate is None:
            if is_shutdown():
                raise ROSInterruptException("ROS shutdown request")
            return
        with mapped():
            self._rate.sleep()


def _guarded(callback: Callable[[Any], Any]) -> Callable[[Any], Any]:
    """A timer callback interrupted by shutdown (``rospy.sleep`` inside it) ends the timer quietly."""

    def run(event: Any) -> Any:
        try:
            return callback(event)
        except ROSInterruptException:
            return None

    return run


def _report(exc: BaseException) -> None:
    _process.log.error("Timer callback raised %s: %s", type(exc).__name__, exc)


class Timer:
    """Call ``callback(TimerEvent)`` every ``period`` (a Duration or seconds) on its own thread."""

    def __init__(
        self,
        period: Duration | float,
        callback: Callable[[Any], Any],
        oneshot: bool = False,
        reset: bool = False,
    ) -> None:
        self._period = period
        self._callback = callback
        self._oneshot = oneshot
        self._timer = _timers.Timer(
            _process.clock,
            period,
            _guarded(callback),
            oneshot=oneshot,
            make_time=Time.from_sec,
            on_error=_report,
        )

    def shutdown(self) -> None:
        """Stop the timer."""
        self._timer.shutdown()

    def is_alive(self) -> bool:
        return self._timer.is_alive()

    def join(self, timeout: float | None = None) -> None:
        self._timer.join(timeout)
