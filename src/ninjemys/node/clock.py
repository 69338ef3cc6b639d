"""ROS time for a node: the wall clock, or simulated time driven by /clock.

When the parameter ``/use_sim_time`` is true at node start, ROS time is whatever the last
``rosgraph_msgs/Clock`` message on ``/clock`` said, and 0 until the first one arrives (ROS 1 semantics,
so ``rospy.get_time()`` reads 0.0 before ``rosbag play --clock`` starts). Otherwise ROS time is
``time.time()``.

Everything that waits on ROS time (``sleep``, ``Rate``, ``Timer``) waits here. In simulated time
each waiter blocks on its own condition (sharing the clock's lock) and a /clock message notifies only
the waiters whose time has come (a simulator publishes /clock every physics step: waking every
sleeper on each one cost move_base about a third of its CPU); in wall time each waiter
blocks on its own thread's "gate" lock for exactly the remaining interval (one futex wait, as cheap as
``time.sleep``), and :meth:`Clock.wake` / :meth:`Clock.shutdown` open every gate. There is no polling
loop. Shutdown wakes every
waiter at once, which is what makes Ctrl-C end a node promptly. A simulated clock that jumps
backwards (``rosbag play --loop``) bumps an epoch counter, so waiters can tell a jump from progress.
"""

from __future__ import annotations

import enum
import threading
import time
from collections.abc import Callable

from ninjemys import interrupt

TYPE_CHECKING = False  # importing typing costs ~7 ms of every node's start-up; checkers set it
if TYPE_CHECKING:
    from typing import Any


USE_SIM_TIME = "/use_sim_time"
CLOCK_TOPIC = "/clock"


class Wake(enum.Enum):
    """Why :meth:`Clock.wait_until` returned."""

    REACHED = "reached"
    SHUTDOWN = "shutdown"
    MOVED_BACKWARDS = "moved_backwards"
    CANCELLED = "cancelled"


class Clock:
    """The ROS clock of one node (wall time unless ``sim`` is true).

    ``now()`` is in seconds as a float; ``now_ns()`` gives exact integer nanoseconds, which is what
    ``Time.now()`` is built from so simulated stamps round-trip bit-exactly.
    """

    def __init__(self, sim: bool = False, wall: Callable[[], float] = time.time) -> None:
        self.is_sim = sim
        self._wall = wall
        self._sim_ns = 0
        self._epoch = 0
        self._shutdown = False
        self._lock = threading.Lock()
        self._cond = threading.Condition(self._lock)
        #: simulated-time waiters: each thread's own condition on the clock's lock -> its target
        self._sim_waiters: dict[threading.Condition | _MainSimWaiter, float] = {}
        self._subscription: Any = None
        # wall-time sleepers wait on a per-thread "gate" lock with a timeout (one futex wait, as cheap as
        # time.sleep); wake() and shutdown() release every registered gate
        self._gates: set[Any] = set()
        self._gates_lock = threading.Lock()
        self._local = threading.local()

    # -- reading ------------------------------------------------------------------------------------
    def now(self) -> float:
        """ROS time in seconds (0.0 in simulated time until the first /clock message)."""
        if self.is_sim:
            return self._sim_ns / 1e9
        return self._wall()

    def now_ns(self) -> int:
        """ROS time in integer nanoseconds."""
        if self.is_sim:
            return self._sim_ns
        return time.time_ns() if self._wall is time.time else int(self._wall() * 1e9)

    @property
    def is_wallclock(self) -> bool:
        return not self.is_sim

    @property
    def epoch(self) -> int:
        """Incremented each time simulated time jumps backwards."""
        return self._epoch

    @property
    def is_shutdown(self) -> bool:
        return self._shutdown

    # -- driving (simulated time) ----------------------------------------------------------------------
    def set_time_ns(self, ns: int) -> None:
        """Set simulated time (the /clock callback); a backwards step starts a new epoch."""
        with self._cond:
            if ns < self._sim_ns:
                self._epoch += 1
                self._sim_ns = ns
                self._notify_all()
                return
            self._sim_ns = ns
            now = ns / 1e9
            for waiter, target in self._sim_waiters.items():
                if target - now <= 0:
                    waiter.notify()

    def _notify_all(self) -> None:
        """Wake every simulated-time waiter (the clock's lock held)."""
        for waiter in self._sim_waiters:
            waiter.notify()

    def switch_to_sim(self) -> None:
        """Start following simulated time (at init_node, when /use_sim_time is set).

        Waiters that started in wall time (a Rate or Timer made before init_node) are woken as after a
        backwards jump, so they re-anchor on simulated time instead of waiting for a wall-clock date.
        """
        with self._cond:
            if self.is_sim:
                return
            self.is_sim = True
            self._epoch += 1
            self._notify_all()
        self._open_gates()

    def set_time(self, secs: int, nsecs: int = 0) -> None:
        self.set_time_ns(int(secs) * 1_000_000_000 + int(nsecs))

    def on_clock_message(self, msg: Any) -> None:
        """Subscriber callback for rosgraph_msgs/Clock."""
        stamp = msg.clock
        self.set_time(stamp.secs, stamp.nsecs)

    # -- waiting ----------------------------------------------------------------------------------------
    def wake(self) -> None:
        """Wake every waiter so it re-checks its own cancel condition (Timer.shutdown uses this)."""
        with self._cond:
            self._notify_all()
        self._open_gates()

    def shutdown(self) -> None:
        """Wake every waiter for good: all current and future waits return SHUTDOWN."""
        with self._cond:
            self._shutdown = True
            self._notify_all()
        self._open_gates()
        sub, self._subscription = self._subscription, None
        if sub is not None:
            try:
                sub.unregister()
            except Exception:  # the node may already be gone; nothing left to release
                pass

    def wait_until(self, target: float, cancelled: Callable[[], bool] | None = None) -> Wake:
        """Block until ROS time reaches ``target`` seconds, shutdown, a backwards jump, or ``cancelled()``."""
        if not self.is_sim:
            return self._wall_wait(target, cancelled)
        waiter = getattr(self._local, "waiter", None)
        if waiter is None:
            # the main thread's own never wakes to check (interrupt.wait_event); others' a Condition
            waiter = (
                _MainSimWaiter(self._lock) if interrupt.on_main_thread() else threading.Condition(self._lock)
            )
            self._local.waiter = waiter
        with self._cond:
            epoch = self._epoch
            self._sim_waiters[waiter] = target
            try:
                while True:
                    wake = self._why_awake(epoch, cancelled, target - self.now())
                    if wake is not None:
                        return wake
                    waiter.wait()
            finally:
                del self._sim_waiters[waiter]

    def _why_awake(self, epoch: int, cancelled: Callable[[], bool] | None, remaining: float) -> Wake | None:
        """Why a sleeper must return now (shutdown first, then cancel, a time jump, the time reached), or None."""
        if self._shutdown:
            return Wake.SHUTDOWN
        if cancelled is not None and cancelled():
            return Wake.CANCELLED
        if self._epoch != epoch:
            return Wake.MOVED_BACKWARDS
        if remaining <= 0:
            return Wake.REACHED
        return None

    def _gate(self) -> Any:
        gate = getattr(self._local, "gate", None)
        if gate is None:
            if interrupt.on_main_thread():
                gate = _MainGate()  # a long rospy.sleep on the main thread never wakes to check
            else:
                gate = threading.Lock()
                gate.acquire()
            self._local.gate = gate
        return gate

    def _open_gates(self) -> None:
        with self._gates_lock:
            gates = list(self._gates)
        for gate in gates:
            try:
                gate.release()
            except RuntimeError:
                pass  # already opened and not yet re-armed by its sleeper

    def _wall_wait(self, target: float, cancelled: Callable[[], bool] | None) -> Wake:
        """Wall-time wait: sleep on this thread's gate until ``target``; an opened gate means re-check."""
        gate = self._gate()
        epoch = self._epoch
        with self._gates_lock:
            self._gates.add(gate)
        try:
            while True:
                remaining = target - self._wall()
                wake = self._why_awake(epoch, cancelled, remaining)  # an epoch change: now simulated
                if wake is not None:
                    return wake
                # True: someone opened the gate (we hold it again, re-armed); False: the time is up
                gate.acquire(True, remaining)
        finally:
            with self._gates_lock:
                self._gates.discard(gate)

    def wait_for(self, seconds: float, cancelled: Callable[[], bool] | None = None) -> Wake:
        """Sleep ``seconds`` of ROS time (see :meth:`wait_until`)."""
        return self.wait_until(self.now() + seconds, cancelled)

    # -- wiring to a node -------------------------------------------------------------------------------
    def subscribe(self, node: Any, clock_class: type) -> None:
        """Follow ``/clock`` on ``node`` (queue 1: only the newest time matters)."""
        self._subscription = node.subscriber(CLOCK_TOPIC, clock_class, self.on_clock_message, queue_size=1)

    def install(self) -> None:
        """Make ``ninjemys.rostime.Time.now()`` read this clock (a Node does this through
        ``rostime.claim_default_clock`` when it becomes the process's default node)."""
        from ninjemys import rostime

        rostime.set_clock(self.now_pair)

    def now_pair(self) -> tuple[int, int]:
        """ROS time as (secs, nsecs), the form ``ninjemys.rostime`` clock hooks return."""
        return divmod(self.now_ns(), 1_000_000_000)


class FakeClock(Clock):
    """A simulated clock that tests drive by hand: ``clock.advance(0.1)`` wakes sleepers due by then."""

    def __init__(self, start: float = 0.0) -> None:
        super().__init__(sim=True)
        self._sim_ns = int(round(start * 1e9))

    def advance(self, seconds: float) -> None:
        self.set_time_ns(self._sim_ns + int(round(seconds * 1e9)))

    def set(self, seconds: float) -> None:
        self.set_time_ns(int(round(seconds * 1e9)))


def for_node(node: Any) -> Clock:
    """The clock of ``node``: a :class:`~ninjemys.node.Node` owns one (``node.clock``, wall or simulated
    as ``/use_sim_time`` said at its start); for another object with ``get_param`` and ``subscriber``,
    a new clock following ``/clock`` when ``/use_sim_time`` is true."""
    own = getattr(node, "clock", None)
    if isinstance(own, Clock):
        return own
    try:
        sim = bool(node.get_param(USE_SIM_TIME, False))
    except Exception:  # an unreachable parameter server means no sim time, as in rospy
        sim = False
    clock = Clock(sim=sim)
    if sim:
        from ninjemys.idl.loader import get_message_class

        clock.subscribe(node, get_message_class("rosgraph_msgs/Clock"))
    return clock


class _MainGate:
    """The main thread's wall-time gate: the lock-gate's two calls over an :class:`interrupt.Event`,
    so the sleep waits in :func:`interrupt.wait_event`: no periodic wake-up, and a signal that landed
    on any thread runs its handler at once (a worker thread's gate is a plain lock, never sliced)."""

    def __init__(self) -> None:
        self._event = interrupt.Event()

    def acquire(self, blocking: bool = True, timeout: float = -1) -> bool:
        """Wait until opened (True, re-armed) or ``timeout`` seconds pass (False)."""
        opened = interrupt.wait_event(self._event, timeout if blocking and timeout >= 0 else None)
        self._event.clear()
        return opened

    def release(self) -> None:
        self._event.set()


class _MainSimWaiter:
    """The main thread's simulated-time waiter: a Condition's ``wait``/``notify`` on the clock's lock
    over an :class:`interrupt.Event` (a sim-time ``rospy.sleep`` on the main thread used to wake 5
    times a second; a signal on any thread still ends it at once)."""

    def __init__(self, lock: threading.Lock) -> None:
        self._lock = lock
        self._event = interrupt.Event()

    def notify(self) -> None:
        """Called with the clock's lock held."""
        self._event.set()

    def wait(self) -> None:
        """Called with the clock's lock held: released while waiting, held again on return (the caller
        re-checks its condition under it, so a notify between the wake-up and the clear is not lost)."""
        self._lock.release()
        try:
            interrupt.wait_event(self._event)
        finally:
            self._lock.acquire()
        self._event.clear()
