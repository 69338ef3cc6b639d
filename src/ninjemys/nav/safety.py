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
  allowed. :func:`blocked_arcs` is the same test for many commands at once: the local planner drops
  the arcs the monitor would refuse (a planner and a guard that disagree leave the robot standing,
  its linear speed cut again and again, until move_base gives up on an "oscillation").
- :class:`StopZone` holds the test's parameters, so the monitor and the planner use one set, and
  :func:`judged_speed` the speed the monitor judges a command at (the odometry's while braking).
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


@dataclass(frozen=True)
class StopZone:
    """The stop zone's parameters (the monitor's ``~robot_radius`` or ``~footprint``, ``~safety_margin``,
    ``~max_decel``, ``~reaction_time``, ``~obstacle_speed``; ``steps``: points along each arc)."""

    radius: float = 0.12
    margin: float = 0.05
    max_decel: float = 1.0
    reaction_time: float = 0.15
    obstacle_speed: float = 0.0
    steps: int = 12


def scan_points(
    ranges: np.ndarray,
    angles: np.ndarray,
    range_min: float,
    range_max: float,
    sensor: tuple[float, float, float],
) -> np.ndarray:
    """A laser scan's returns as points (n, 2) in the base frame, the sensor at ``sensor`` (x, y, yaw)
    there: -inf is a return at ``range_min`` (REP 117: closer than that), NaN, +inf and out-of-range
    readings are no return. The monitor and the planner's stop-zone check read scans this one way."""
    ranges = np.where(np.isneginf(ranges), range_min, ranges)
    ok = np.isfinite(ranges) & (ranges >= range_min) & (ranges <= range_max)
    r, a = ranges[ok], angles[ok] + sensor[2]
    return np.column_stack([sensor[0] + r * np.cos(a), sensor[1] + r * np.sin(a)])


def stop_distance(v: float, max_decel: float, reaction_time: float) -> float:
    v = abs(v)
    return v * reaction_time + v * v / (2.0 * max(max_decel, 1e-6))


def judged_speed(v: np.ndarray | float, current: float) -> np.ndarray:
    """The speed the monitor judges command ``v`` at: ``v`` itself, or the robot's ``current`` speed
    while ``v`` only slows it down (the robot still moves at ``current`` until it has braked)."""
    v = np.asarray(v, dtype=float)
    keep = (np.abs(v) >= abs(current)) | (v * current <= 0.0)
    return np.where(keep, v, current)


def blocked_arcs(points: np.ndarray, v: np.ndarray, w: np.ndarray, zone: StopZone) -> np.ndarray:
    """:func:`blocked` for many commands at once: a bool per (v[i], w[i]) (same shapes, 1-D)."""
    v = np.asarray(v, dtype=float).ravel()
    w = np.asarray(w, dtype=float).ravel()
    out = np.zeros(v.shape, dtype=bool)
    moving = v != 0.0
    if len(points) == 0 or not moving.any():
        return out
    vm, wm = v[moving], w[moving]
    decel = max(zone.max_decel, 1e-6)
    horizon = zone.reaction_time + np.abs(vm) / decel
    clearance = zone.radius + zone.margin + zone.obstacle_speed * horizon
    travel = np.abs(vm) * horizon
    d_now_all = np.hypot(points[:, 0], points[:, 1])
    near = points[d_now_all < float((clearance + travel).max())]  # no other point can come that close
    if len(near) == 0:
        return out
    d_now = np.hypot(near[:, 0], near[:, 1])
    t = horizon[:, None] * (np.arange(1, zone.steps + 1) / zone.steps)[None, :]  # (n, steps)
    straight = np.abs(wm) < 1e-6
    wsafe = np.where(straight, 1.0, wm)[:, None]
    px = np.where(straight[:, None], vm[:, None] * t, vm[:, None] / wsafe * np.sin(wsafe * t))
    py = np.where(straight[:, None], 0.0, vm[:, None] / wsafe * (1.0 - np.cos(wsafe * t)))
    # squared distances (commands, steps, points), the closest approach along each arc
    d2 = np.square(near[None, None, :, 0] - px[:, :, None]) + np.square(
        near[None, None, :, 1] - py[:, :, None]
    )
    d_future = np.sqrt(d2.min(axis=1))  # (commands, points)
    hit = (d_future < clearance[:, None]) & (d_future < d_now[None, :] - 1e-3)
    out[moving] = hit.any(axis=1)
    return out


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
    zone = StopZone(radius, margin, max_decel, reaction_time, obstacle_speed, steps=steps)
    return bool(blocked_arcs(points, np.array([v]), np.array([w]), zone)[0])
