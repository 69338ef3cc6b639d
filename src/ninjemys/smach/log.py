"""smach's replaceable log functions and shutdown check.

smach logs through four functions and asks one predicate whether to stop; smach_ros swaps in rospy's
logging and ``rospy.is_shutdown``. The defaults print ``[  INFO ] : ...`` lines to stdout, as smach
does when no ROS is around.
"""

from __future__ import annotations

from collections.abc import Callable

LogFn = Callable[[str], object]


def _printer(tag: str) -> LogFn:
    def log(msg: object) -> None:
        print(f"[{tag}] : {msg}")

    return log


class _Hooks:
    """The current loggers and shutdown predicate (one per process, as in smach)."""

    info: LogFn = _printer("  INFO ")
    warn: LogFn = _printer("  WARN ")
    debug: LogFn = _printer(" DEBUG ")
    error: LogFn = _printer(" ERROR ")
    shutdown: Callable[[], bool] = staticmethod(lambda: False)


def loginfo(msg: object) -> None:
    _Hooks.info(str(msg))


def logwarn(msg: object) -> None:
    _Hooks.warn(str(msg))


def logdebug(msg: object) -> None:
    _Hooks.debug(str(msg))


def logerr(msg: object) -> None:
    _Hooks.error(str(msg))


def set_loggers(info: LogFn, warn: LogFn, debug: LogFn, error: LogFn) -> None:
    """Route smach's log lines elsewhere (smach_ros passes rospy.loginfo, logwarn, logdebug, logerr)."""
    _Hooks.info, _Hooks.warn, _Hooks.debug, _Hooks.error = info, warn, debug, error


def is_shutdown() -> bool:
    """True once the process is shutting down: running containers stop between states."""
    return bool(_Hooks.shutdown())


def set_shutdown_check(cb: Callable[[], bool]) -> None:
    """Use ``cb`` (e.g. ``rospy.is_shutdown``) to decide when containers stop."""
    _Hooks.shutdown = cb
