"""The one piece of global state of the rospy facade: the node of this process.

rospy's API is module-level functions, so something must remember "the" node. Here that is a single
:class:`_Process` instance holding the core :class:`~ninjemys.node.Node` (None until ``init_node``),
the handles created before ``init_node`` (the seeds create their Publisher first), and the user's
shutdown hooks. The node owns its clock, logging, /rosout and logger services; before ``init_node``
rospy's calls use a wall clock and a console-only log, which ``init_node`` hands to the node (so a
Rate made before ``init_node`` follows the node's simulated time). All behaviour lives in the core.

``ninjemys.testing.reset_rospy()`` shuts the node down and empties this state in-process, so tests
can call ``init_node`` again without a new interpreter.
"""

from __future__ import annotations

import threading
from collections.abc import Callable

from ninjemys.node.clock import Clock
from ninjemys.node.log import DEBUG, ERROR, FATAL, INFO, WARN, NodeLog
from rospy.exceptions import ROSInitException

TYPE_CHECKING = False  # importing typing costs ~7 ms of every node's start-up; checkers set it
if TYPE_CHECKING:
    from typing import Any

__all__ = [
    "DEBUG",
    "INFO",
    "WARN",
    "ERROR",
    "FATAL",
    "is_shutdown",
    "signal_shutdown",
    "on_shutdown",
    "get_node_uri",
    "is_initialized",
]


class _Process:
    """State shared by the whole facade (one per process, like rospy's module globals)."""

    def __init__(self) -> None:
        self.lock = threading.RLock()
        self.reset()

    def reset(self) -> None:
        """Forget the node and everything hung off it (the caller shut the node down first)."""
        with self.lock:
            self.node: Any = None
            #: what rospy's time and logging calls use before init_node (init_node hands the clock over)
            self.preinit_clock = Clock()
            self.preinit_log = NodeLog("/unnamed", write_file=False)
            self.pending: list[Any] = []
            self.waiters: set[threading.Event] = set()
            self.hooks: list[Callable[[], Any]] = []
            self.hooks_ran = False
            self.shutdown_requested = False
            self.init_args: tuple[Any, ...] | None = None
            #: rospy.service's ``/unnamed`` stand-in for master calls made before init_node
            self.unnamed: Any = None

    @property
    def clock(self) -> Clock:
        """The node's clock, or the pre-init_node wall clock."""
        node = self.node
        return self.preinit_clock if node is None else node.clock

    @property
    def log(self) -> NodeLog:
        """The node's log, or the console-only log of rospy's calls before init_node."""
        node = self.node
        return self.preinit_log if node is None else node.log

    def require_node(self) -> Any:
        node = self.node
        if node is None:
            raise ROSInitException("ROS node has not been initialized yet. Please call init_node() first")
        return node

    def attach(self, handle: Any) -> None:
        """Bind a Publisher/Subscriber/Service to the node now, or at init_node if there is none yet."""
        with self.lock:
            if self.node is None:
                self.pending.append(handle)
                return
        handle._bind(self.node)

    def run_hooks(self) -> None:
        """Run user shutdown hooks once, before the node tears down (rospy's order)."""
        with self.lock:
            if self.hooks_ran:
                return
            self.hooks_ran = True
            hooks = list(self.hooks)
        for hook in hooks:
            try:
                hook()
            except Exception as exc:  # one bad hook must not stop the others or the teardown
                self.log.error("on_shutdown hook %r raised: %s", hook, exc)


_process = _Process()


def warn_illegal_name(name: str, stacklevel: int = 3) -> None:
    """rospy's warning (never an error) for a graph name ROS 1 calls illegal (``a b``, ``1x``, ``a-b``).

    rospy warns and carries on, and so do we: the master decides what it registers (it refuses
    names with a space or a colon, which the node then logs at FATAL, as rospy does).
    """
    from ninjemys.names import is_legal_name

    if not is_legal_name(name):
        import warnings

        warnings.warn(
            f"'{name}' is not a legal ROS graph resource name. This may cause problems with other ROS tools",
            stacklevel=stacklevel,
        )


def process_node() -> Any:
    """The core :class:`~ninjemys.node.Node` that ``init_node`` created for this process.

    The library facades (actionlib, tf2_ros, message_filters, dynamic_reconfigure ...) build their
    ninjemys cores on it, so a ROS 1 program that calls ``rospy.init_node`` first just works.
    Raises ROSInitException before ``init_node``.
    """
    return _process.require_node()


def is_initialized() -> bool:
    """True once init_node has registered the node."""
    return _process.node is not None


def is_shutdown() -> bool:
    """True once the node is shutting down (Ctrl-C, rosnode kill, a name collision, signal_shutdown)."""
    if _process.shutdown_requested:
        return True
    node = _process.node
    return node is not None and node.is_shutdown


def signal_shutdown(reason: str) -> None:
    """Initiate shutdown: user hooks first, then the node tears down; sleeps and spin() return at once."""
    with _process.lock:
        _process.shutdown_requested = True
    node = _process.node
    _process.run_hooks()
    _process.clock.shutdown()
    if node is not None:
        node.shutdown(reason)


def _reset() -> None:
    """Shut the process's node down (user hooks first) and forget every piece of rospy state.

    For tests, through ``ninjemys.testing.reset_rospy()``: the next ``init_node`` starts afresh.
    """
    node = _process.node
    signal_shutdown("rospy reset")
    if node is not None:
        node.shutdown("rospy reset")  # waits for a shutdown that another thread started
    for handle in list(_process.pending):
        handle.unregister()
    _process.reset()


def on_shutdown(hook: Callable[[], Any]) -> None:
    """Call ``hook()`` (no arguments) when the node shuts down, before its connections close.

    TypeError at once for a hook that cannot be called, as rospy (not an error logged at shutdown).
    """
    if not callable(hook):
        raise TypeError(f"shutdown hook [{hook}] must be a function or callable object: {type(hook)}")
    with _process.lock:
        if not _process.hooks_ran:
            _process.hooks.append(hook)
            return
    hook()


def get_node_uri() -> str | None:
    """The node's slave XML-RPC URI (None before init_node)."""
    node = _process.node
    return None if node is None else node.uri


# -- logging: the user-facing calls ---------------------------------------------------------------------


def logdebug(msg: Any, *args: Any, **kwargs: Any) -> None:
    _process.log.log(DEBUG, msg, *args, depth=2, exc_info=bool(kwargs.get("exc_info")))


def loginfo(msg: Any, *args: Any, **kwargs: Any) -> None:
    _process.log.log(INFO, msg, *args, depth=2, exc_info=bool(kwargs.get("exc_info")))


def logwarn(msg: Any, *args: Any, **kwargs: Any) -> None:
    _process.log.log(WARN, msg, *args, depth=2, exc_info=bool(kwargs.get("exc_info")))


def logerr(msg: Any, *args: Any, **kwargs: Any) -> None:
    _process.log.log(ERROR, msg, *args, depth=2, exc_info=bool(kwargs.get("exc_info")))


def logfatal(msg: Any, *args: Any, **kwargs: Any) -> None:
    _process.log.log(FATAL, msg, *args, depth=2, exc_info=bool(kwargs.get("exc_info")))


logout = loginfo
logerror = logerr
logwarning = logwarn


def _throttled(level: int) -> Callable[..., None]:
    def log_throttle(period: float, msg: Any, *args: Any, **_kwargs: Any) -> None:
        _process.log.log_throttle(period, level, msg, *args, depth=2)

    return log_throttle


def _once(level: int) -> Callable[..., None]:
    def log_once(msg: Any, *args: Any, **_kwargs: Any) -> None:
        _process.log.log_once(level, msg, *args, depth=2)

    return log_once


def _identical(level: int) -> Callable[..., None]:
    def log_throttle_identical(period: float, msg: Any, *args: Any, **_kwargs: Any) -> None:
        _process.log.log_throttle_identical(period, level, msg, *args, depth=2)

    return log_throttle_identical


logdebug_throttle, loginfo_throttle, logwarn_throttle, logerr_throttle, logfatal_throttle = (
    _throttled(lvl) for lvl in (DEBUG, INFO, WARN, ERROR, FATAL)
)
logdebug_once, loginfo_once, logwarn_once, logerr_once, logfatal_once = (
    _once(lvl) for lvl in (DEBUG, INFO, WARN, ERROR, FATAL)
)
(
    logdebug_throttle_identical,
    loginfo_throttle_identical,
    logwarn_throttle_identical,
    logerr_throttle_identical,
    logfatal_throttle_identical,
) = (_identical(lvl) for lvl in (DEBUG, INFO, WARN, ERROR, FATAL))
