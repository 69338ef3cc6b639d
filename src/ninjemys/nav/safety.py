"""The safety monitor's decisions, with no ROS inside: which command wins, and whether it is safe.

- :class:`TwistMux` picks, like twist_mux, the highest-priority input whose last command is younger
  than its timeout (the watchdog: a stale input no longer counts; no input at all means stop) and
  that no active lock masks (a :class:`MuxLock` that is true, or silent past its timeout, masks
  every input of lower priority than its own).
- :func:`stop_distance` is how far the robot travels before it stands still from speed ``v``:
  ``v * reaction_time + v^2 / (2 * max_decel)``.
- :func:`blocked` says whether the motion, held for the reaction time and then braked, would bring
  the body (plus a margin) closer to a laser point it is not already moving away from: the stop zone
  is what the footprint sweeps along the commanded arc, so turning in place and backing away stay
  allowed.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

NEVER = -1e9  # the last_time of a source that has sent nothing yet


@dataclass
class MuxInput:
    """One command source: its name, topic, priority (higher wins) and timeout (seconds; 0: none,
    as in twist_mux, so its last command holds until another input takes over)."""

    name: str
    topic: str
    priority: int
    timeout: float
    last_time: float = NEVER
    v: float = 0.0
    w: float = 0.0

    def fresh(self, now: float) -> bool:
        if self.last_time == NEVER:
            return False
        return self.timeout <= 0.0 or now - self.last_time <= self.timeout


@dataclass
class MuxLock:
    """twist_mux's lock: a std_msgs/Bool topic that, while true, or while silent longer than its
    timeout (0: never), masks every input whose priority is below the lock's."""

    name: str
    topic: str
    priority: int
    timeout: float
    last_time: float = NEVER
    data: bool = False

    def locked(self, now: float) -> bool:
        return self.data or (self.timeout > 0.0 and now - self.last_time > self.timeout)


class TwistMux:
    """twist_mux's selection over :class:`MuxInput` s, masked by :class:`MuxLock` s."""

    def __init__(self, inputs: list[MuxInput], locks: list[MuxLock] | None = None) -> None:
        self.inputs = sorted(inputs, key=lambda i: -i.priority)
        self.locks = list(locks or [])

    def lock_priority(self, now: float) -> int:
        """The highest priority among the active locks (0 when none is: nothing is masked)."""
        return max((lock.priority for lock in self.locks if lock.locked(now)), default=0)

    def masked(self, inp: MuxInput, now: float) -> bool:
        """twist_mux's masking: stale, or below the priority of an active lock."""
        return not inp.fresh(now) or inp.priority < self.lock_priority(now)

    def select(self, now: float, allowed: set[str] | None = None) -> MuxInput | None:
        """The unmasked input of highest priority (among ``allowed`` names), or None."""
        floor = self.lock_priority(now)
        for inp in self.inputs:
            if (allowed is None or inp.name in allowed) and inp.fresh(now) and inp.priority >= floor:
                return inp
        return None


def stop_distance(v: float, max_decel: float, reaction_time: float) -> float:
    v = abs(v)
    return v * reaction_time + v * v / (2.0 * max(max_decel, 1e-6))


def blocked(
    points: np.ndarray,
    v: float,
    w: float,
    radius: float,
    margin: float,
    max_decel: float,
    reaction_time: float,
    obstacle_speed: float = 0.0,
    steps: int = 12,
) -> bool:
    """True when moving at (v, w) until standing still would bring the body closer than
    ``radius + margin + obstacle_speed * T`` to a laser point (n, 2, base frame) that it is not
    already moving away from. ``T`` is the reaction time plus the braking time; the robot's path over
    ``T`` is the arc of (v, w). ``obstacle_speed`` covers people walking towards the robot meanwhile.
    """
    if v == 0.0 or len(points) == 0:
        return False
    horizon = reaction_time + abs(v) / max(max_decel, 1e-6)
    clearance = radius + margin + obstacle_speed * horizon
    travel = abs(v) * horizon
    near = points[np.hypot(points[:, 0], points[:, 1]) < clearance + travel]
    if len(near) == 0:
        return False
    t = np.linspace(0.0, horizon, steps + 1)[1:]
    if abs(w) < 1e-6:
        px, py = v * t, np.zeros_like(t)
    else:
        px, py = v / w * np.sin(w * t), v / w * (1.0 - np.cos(w * t))
    d_now = np.hypot(near[:, 0], near[:, 1])
    d_future = np.hypot(near[:, 0:1] - px[None, :], near[:, 1:2] - py[None, :]).min(axis=1)
    return bool(np.any((d_future < clearance) & (d_future < d_now - 1e-3)))
