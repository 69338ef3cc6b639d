"""The safety monitor's decisions, with no ROS inside: which command wins, and whether it is safe.

- :class:`TwistMux` picks, like twist_mux, the highest-priority input whose last command is younger
  than its timeout (the watchdog: a stale input no longer counts; no input at all means stop).
- :func:`stop_distance` is how far the robot travels before it stands still from speed ``v``:
  ``v * reaction_time + v^2 / (2 * max_decel)``.
- :func:`blocked` says whether any laser point (base frame) lies in the stop zone: the band swept by
  the footprint (half-width ``radius + margin``) from the robot's front (or back, when reversing) out
  to ``radius + margin + stop_distance``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class MuxInput:
    """One command source: its name, topic, priority (higher wins) and timeout (seconds)."""

    name: str
    topic: str
    priority: int
    timeout: float
    last_time: float = -1e9
    v: float = 0.0
    w: float = 0.0

    def fresh(self, now: float) -> bool:
        return now - self.last_time <= self.timeout


class TwistMux:
    """twist_mux's selection over :class:`MuxInput` s."""

    def __init__(self, inputs: list[MuxInput]) -> None:
        self.inputs = sorted(inputs, key=lambda i: -i.priority)

    def select(self, now: float, allowed: set[str] | None = None) -> MuxInput | None:
        """The fresh input of highest priority (among ``allowed`` names), or None."""
        for inp in self.inputs:
            if (allowed is None or inp.name in allowed) and inp.fresh(now):
                return inp
        return None


def stop_distance(v: float, max_decel: float, reaction_time: float) -> float:
    v = abs(v)
    return v * reaction_time + v * v / (2.0 * max(max_decel, 1e-6))


def blocked(
    points: np.ndarray, v: float, radius: float, margin: float, max_decel: float, reaction_time: float
) -> bool:
    """True when a point (n, 2) in the base frame is in the stop zone for moving at ``v``."""
    if v == 0.0 or len(points) == 0:
        return False
    reach = radius + margin + stop_distance(v, max_decel, reaction_time)
    x = points[:, 0] if v > 0 else -points[:, 0]
    y = points[:, 1]
    return bool(np.any((x > 0) & (x < reach) & (np.abs(y) < radius + margin)))
