"""The simulator's pacing: one thread steps a simulation against the wall clock and owns sim time.

No ROS in here. :class:`Stepper` calls a step function (which advances the physics and publishes) as
fast as possible (``rate`` 0) or at ``rate`` times real time, pauses and resumes (Gazebo's
pause/unpause_physics), catches up after a reset of time, and counts what it stepped for the
summary the node logs on exit. :class:`StepLock` lets everyone else (services, the browser view,
spawns) get the simulation between two steps; :class:`Due` schedules periodic outputs in sim time.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from dataclasses import dataclass

from ninjemys.errors import ShutdownError


class StepLock:
    """The simulation's lock: the stepping thread steps with it, services, the browser view and
    spawns take it with ``with lock:`` (reentrant).

    Running as fast as possible, the stepping thread would take a plain lock again right after
    releasing it (it holds the GIL) and starve everyone else. Yielding the CPU after every step
    (``time.sleep(0)``) fixed that at a price: on a loaded machine each yield let other processes
    run, ~90 us per 10 ms step. Here the others announce that they wait, and the stepping thread
    steps aside (:meth:`give_way`) only then."""

    def __init__(self) -> None:
        self._lock = threading.RLock()
        self._count_lock = threading.Lock()
        self._waiting = 0
        self._nobody_waits = threading.Event()
        self._nobody_waits.set()

    def __enter__(self) -> StepLock:
        with self._count_lock:
            self._waiting += 1
            self._nobody_waits.clear()
        try:
            self._lock.acquire()
        except BaseException:  # interrupted while waiting (KeyboardInterrupt): no longer a waiter
            self._done_waiting()
            raise
        return self

    def __exit__(self, *_exc: object) -> None:
        self._lock.release()
        self._done_waiting()

    def _done_waiting(self) -> None:
        with self._count_lock:
            self._waiting -= 1
            if not self._waiting:
                self._nobody_waits.set()

    @property
    def stepping(self) -> threading.RLock:
        """The lock itself, for the stepping thread (which does not announce itself)."""
        return self._lock

    def give_way(self, timeout: float) -> None:
        """Between two steps: return once nobody waits for the lock (at most ``timeout`` s)."""
        if self._waiting:
            self._nobody_waits.wait(timeout)


@dataclass
class Due:
    """A periodic output in simulated time: fires at the first step at or after ``next``."""

    period: float
    next: float = 0.0

    def fire(self, now: float) -> bool:
        if now + 1e-9 < self.next:
            return False
        self.next = max(self.next + self.period, now - self.period)  # no burst after a pause or reset
        return True


class Stepper:
    """The stepping thread: ``step()`` under the lock, paced by ``rate`` (0: as fast as possible).

    ``sim_time()`` reads the simulated clock (it may go back: reset_simulation); ``dt`` is what one
    step adds; ``on_error`` hears about a step that raised (the thread steps on: one bad step must
    not freeze the simulation for good). A :class:`ShutdownError` ends the thread quietly."""

    def __init__(
        self,
        step: Callable[[], None],
        sim_time: Callable[[], float],
        dt: float,
        rate: float,
        lock: StepLock,
        on_error: Callable[[Exception], None],
        name: str = "puzzlebot-sim",
    ) -> None:
        self._step = step
        self._sim_time = sim_time
        self.dt = dt
        self.rate = rate
        self.lock = lock
        self._on_error = on_error
        self._name = name
        self.paused = False
        self._wake = threading.Event()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._started = (time.monotonic(), time.process_time())
        self.stepped = 0.0  # simulated seconds stepped (resets of time do not undo them)
        self._rebase = False  # the rate changed: pace from the current instant

    def start(self) -> None:
        self._thread = threading.Thread(target=self._run, name=self._name, daemon=True)
        self._thread.start()

    def stop(self, timeout: float = 5.0) -> bool:
        """Stop the thread; True when it had been started (and is now joined)."""
        self._stop.set()
        self._wake.set()
        if self._thread is None:
            return False
        self._thread.join(timeout)
        return True

    def wake(self) -> None:
        """Re-read the pause flag and the clock now (after unpause or a reset)."""
        self._wake.set()

    def set_rate(self, rate: float) -> None:
        """A new real-time factor (0: as fast as possible), paced from now on."""
        with self.lock:
            self.rate = rate
            self._rebase = True
        self._wake.set()

    def set_paused(self, paused: bool) -> None:
        with self.lock:
            self.paused = paused
        self._wake.set()

    def summary(self) -> str:
        """How fast the simulation ran: simulated seconds per wall second and per CPU second."""
        wall = max(time.monotonic() - self._started[0], 1e-9)
        cpu = max(time.process_time() - self._started[1], 1e-9)
        stepped = self.stepped
        return (
            f"simulated {stepped:.2f} s in {wall:.2f} s of wall time ({stepped / wall:.1f}x real time), "
            f"{cpu:.2f} s of CPU ({stepped / cpu:.1f} simulated s per CPU s)"
        )

    def _run(self) -> None:
        self._started = (time.monotonic(), time.process_time())
        wall0 = time.monotonic()
        sim0 = self._sim_time()
        stepping, stopped, step = self.lock.stepping, self._stop.is_set, self._step
        while not stopped():
            try:
                # the pause flag is read under the same hold of the lock as the step (one hold a step)
                with stepping:
                    paused = self.paused
                    if not paused:
                        if self._rebase or self._sim_time() < sim0:  # a new rate, or reset_simulation
                            self._rebase = False
                            wall0, sim0 = time.monotonic(), self._sim_time()
                        step()
                        self.stepped += self.dt
            except ShutdownError:
                return  # the node shut down under the stepping thread
            except Exception as exc:  # a bug in one step must not freeze the simulation for good
                self._on_error(exc)
            if paused:
                self._wake.wait(0.5)
                self._wake.clear()
                wall0, sim0 = time.monotonic(), self._sim_time()
                continue
            if self.rate <= 0:
                self.lock.give_way(0.5)  # as fast as possible, yet services and the view get the lock
            else:
                target = wall0 + (self._sim_time() - sim0) / self.rate
                delay = target - time.monotonic()
                if delay > 0:
                    self._wake.wait(delay)
                    self._wake.clear()
                    continue
                if delay < -0.25:  # far behind (machine busy): run on from now, no burst to catch up
                    wall0, sim0 = time.monotonic(), self._sim_time()
                # behind its rate it steps back to back, as fast as possible: give way as then (a
                # loaded machine had a paced simulator take its lock straight back, and Gazebo's
                # services and spawns waited for it for a minute)
                self.lock.give_way(0.5)
