"""diff_drive_controller's odometry: pose from wheel positions, velocities by a rolling mean.

The wheels' travelled distances (joint position x radius) give the displacement each update: forward
the mean of the two, turning their difference over the separation; the pose integrates it exactly
on an arc (second-order Runge-Kutta when the turn is negligible). The velocities reported are the
mean over the last ``velocity_rolling_window_size`` updates, as the controller publishes them.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field


@dataclass
class Odometry:
    wheel_separation: float
    left_radius: float
    right_radius: float
    window: int = 10
    x: float = 0.0
    y: float = 0.0
    heading: float = 0.0
    linear: float = 0.0
    angular: float = 0.0
    _left: float | None = None
    _right: float | None = None
    _stamp: float | None = None
    _lin: deque = field(default_factory=deque)
    _ang: deque = field(default_factory=deque)

    def reset(self, stamp: float | None = None) -> None:
        """Forget the wheel positions (the next update only records them) and keep the pose."""
        self._left = self._right = None
        self._stamp = stamp
        self._lin.clear()
        self._ang.clear()

    def update(self, left_pos: float, right_pos: float, stamp: float) -> bool:
        """Wheel joint positions (rad) at ``stamp``; False until two updates are ``dt`` > 0 apart."""
        left, right = left_pos * self.left_radius, right_pos * self.right_radius
        if self._left is None or self._right is None or self._stamp is None:
            self._left, self._right, self._stamp = left, right, stamp
            return False
        dl, dr = left - self._left, right - self._right
        self._left, self._right = left, right
        dt = stamp - self._stamp
        if dt < 1e-4:
            return False  # too close together for a velocity; the positions are kept
        self._stamp = stamp
        linear = (dr + dl) * 0.5
        angular = (dr - dl) / self.wheel_separation
        self.integrate(linear, angular)
        self._push(linear / dt, angular / dt)
        return True

    def update_open_loop(self, linear: float, angular: float, stamp: float) -> None:
        """Open loop: integrate the commanded velocities instead of the wheels."""
        dt = 0.0 if self._stamp is None else stamp - self._stamp
        self._stamp = stamp
        self.linear, self.angular = linear, angular
        self.integrate(linear * dt, angular * dt)

    def integrate(self, linear: float, angular: float) -> None:
        if abs(angular) < 1e-6:
            direction = self.heading + angular * 0.5
            self.x += linear * math.cos(direction)
            self.y += linear * math.sin(direction)
            self.heading += angular
        else:
            heading_old = self.heading
            r = linear / angular
            self.heading += angular
            self.x += r * (math.sin(self.heading) - math.sin(heading_old))
            self.y += -r * (math.cos(self.heading) - math.cos(heading_old))

    def _push(self, linear: float, angular: float) -> None:
        for buf, v in ((self._lin, linear), (self._ang, angular)):
            buf.append(v)
            while len(buf) > self.window:
                buf.popleft()
        self.linear = sum(self._lin) / len(self._lin)
        self.angular = sum(self._ang) / len(self._ang)
