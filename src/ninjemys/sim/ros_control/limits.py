"""diff_drive_controller's speed limiter: velocity, acceleration and jerk bounds on one axis.

Parameters are the controller's (``linear/x/has_velocity_limits``, ``max_velocity``, ``min_velocity``
(default: -max), ``has_acceleration_limits``, ``max_acceleration``, ``min_acceleration``,
``has_jerk_limits``, ``max_jerk``, ``min_jerk``). Acceleration is bounded against the previous command
and jerk against the previous two, as the controller does, so a step in cmd_vel becomes a ramp.
"""

from __future__ import annotations

from dataclasses import dataclass


def _clamp(v: float, lo: float, hi: float) -> float:
    return min(max(v, lo), hi)


@dataclass
class SpeedLimiter:
    has_velocity_limits: bool = False
    has_acceleration_limits: bool = False
    has_jerk_limits: bool = False
    min_velocity: float = 0.0
    max_velocity: float = 0.0
    min_acceleration: float = 0.0
    max_acceleration: float = 0.0
    min_jerk: float = 0.0
    max_jerk: float = 0.0

    def limit(self, v: float, v0: float, v1: float, dt: float) -> float:
        """``v`` bounded, given the last command ``v0`` and the one before ``v1``, ``dt`` apart."""
        if dt <= 0:
            return self.limit_velocity(v)
        v = self.limit_jerk(v, v0, v1, dt)
        v = self.limit_acceleration(v, v0, dt)
        return self.limit_velocity(v)

    def limit_velocity(self, v: float) -> float:
        return _clamp(v, self.min_velocity, self.max_velocity) if self.has_velocity_limits else v

    def limit_acceleration(self, v: float, v0: float, dt: float) -> float:
        if not self.has_acceleration_limits:
            return v
        dv = _clamp(v - v0, self.min_acceleration * dt, self.max_acceleration * dt)
        return v0 + dv

    def limit_jerk(self, v: float, v0: float, v1: float, dt: float) -> float:
        if not self.has_jerk_limits:
            return v
        dv, dv0 = v - v0, v0 - v1
        dt2 = 2.0 * dt * dt
        da = _clamp(dv - dv0, self.min_jerk * dt2, self.max_jerk * dt2)
        return v0 + dv0 + da
