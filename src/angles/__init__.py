"""``angles``: the ROS 1 angle helpers (normalize, shortest distance, joint-limit aware distance).

Course code calls these to wrap yaw errors in controllers (``shortest_angular_distance(yaw, goal)``)
and to move revolute joints the short way without crossing a limit. Same names, arguments, return
values and edge cases as ROS Noetic's ``angles`` 1.9 Python module; all angles are radians.
"""

from __future__ import annotations

import math

__all__ = [
    "from_degrees",
    "normalize_angle",
    "normalize_angle_positive",
    "shortest_angular_distance",
    "shortest_angular_distance_with_large_limits",
    "shortest_angular_distance_with_limits",
    "to_degrees",
    "two_pi_complement",
]

_TWO_PI = 2.0 * math.pi


def normalize_angle_positive(angle: float) -> float:
    """``angle`` wrapped into ``[0, 2*pi)``."""
    return angle % _TWO_PI


def normalize_angle(angle: float) -> float:
    """``angle`` wrapped into ``(-pi, pi]``."""
    wrapped = angle % _TWO_PI
    return wrapped - _TWO_PI if wrapped > math.pi else wrapped


def shortest_angular_distance(from_angle: float, to_angle: float) -> float:
    """The signed turn in ``[-pi, pi]`` that takes ``from_angle`` to an angle equivalent to ``to_angle``."""
    return normalize_angle(to_angle - from_angle)


def two_pi_complement(angle: float) -> float:
    """The same direction reached the other way round the circle: ``pi/4`` -> ``-7*pi/4``.

    Angles beyond ``+-2*pi`` are first reduced with ``fmod``; ``0`` maps to ``2*pi``.
    """
    if abs(angle) > _TWO_PI:
        angle = math.fmod(angle, _TWO_PI)
    if angle < 0:
        return _TWO_PI + angle
    if angle > 0:
        return angle - _TWO_PI
    return _TWO_PI


def _min_max_delta(from_angle: float, left_limit: float, right_limit: float) -> tuple[bool, float, float]:
    """How far one may turn from ``from_angle`` before reaching each limit: ``(inside, min, max)``.

    Both directions to each limit are candidates; ``inside`` is False when ``from_angle`` is not in
    the valid arc ``[left_limit, right_limit]`` (limits in ``[-pi, pi]``, the arc may wrap through pi).
    """
    to_left = shortest_angular_distance(from_angle, left_limit)
    to_right = shortest_angular_distance(from_angle, right_limit)
    to_left_other = two_pi_complement(to_left)
    to_right_other = two_pi_complement(to_right)
    if to_left == 0:
        return True, to_left, max(to_right, to_right_other)
    if to_right == 0:
        return True, min(to_left, to_left_other), to_right
    lo, lo_other = (to_left_other, to_left) if to_left_other < to_left else (to_left, to_left_other)
    hi, hi_other = (to_right_other, to_right) if to_right_other > to_right else (to_right, to_right_other)
    if lo <= hi_other or hi >= lo_other:
        # the limits do not bracket from_angle, unless they are the whole circle
        return left_limit == -math.pi and right_limit == math.pi, hi_other, lo_other
    return True, lo, hi


def _pick(prefer_max: bool | None, delta: float, other: float) -> float:
    if prefer_max is None:
        return delta if abs(delta) < abs(other) else other
    return max(delta, other) if prefer_max else min(delta, other)


def shortest_angular_distance_with_limits(
    from_angle: float, to_angle: float, left_limit: float, right_limit: float
) -> tuple[bool, float]:
    """``(valid, delta)``: the turn from ``from_angle`` to ``to_angle`` that stays in ``[left_limit, right_limit]``.

    The valid arc goes counter-clockwise from ``left_limit`` to ``right_limit`` (``(0.25, -0.25)`` is
    the arc through pi). ``valid`` is False when either end lies outside the arc; ``delta`` is then the
    best-effort turn that heads for the nearer limit.
    """
    inside, min_delta, max_delta = _min_max_delta(from_angle, left_limit, right_limit)
    delta = shortest_angular_distance(from_angle, to_angle)
    other = two_pi_complement(delta)
    if inside:
        if min_delta <= delta <= max_delta:
            return True, delta
        if min_delta <= other <= max_delta:
            return True, other
        _, min_to, max_to = _min_max_delta(to_angle, left_limit, right_limit)
        nearer: bool | None = None if abs(min_to) == abs(max_to) else abs(min_to) < abs(max_to)
        return False, _pick(nearer, delta, other)
    nearer = None if abs(min_delta) == abs(max_delta) else abs(min_delta) > abs(max_delta)
    return False, _pick(nearer, delta, other)


def shortest_angular_distance_with_large_limits(
    from_angle: float, to_angle: float, left_limit: float, right_limit: float
) -> tuple[bool, float]:
    """Like :func:`shortest_angular_distance_with_limits` for limits beyond ``[-pi, pi]`` (``left < right``).

    ``delta`` is the shorter of the two ways round whose end stays within the limits; ``valid`` also
    needs ``from_angle`` itself within them.
    """
    delta = shortest_angular_distance(from_angle, to_angle)
    other = two_pi_complement(delta)
    if abs(delta) > abs(other):
        delta, other = other, delta
    if left_limit > right_limit:
        return False, delta
    from_inside = left_limit <= from_angle <= right_limit
    for candidate in (delta, other):
        if left_limit <= from_angle + candidate <= right_limit:
            return from_inside, candidate
    return False, delta


def from_degrees(degrees: float) -> float:
    """Degrees to radians (the C++ API's ``angles::from_degrees``)."""
    return degrees * math.pi / 180.0


def to_degrees(radians: float) -> float:
    """Radians to degrees (the C++ API's ``angles::to_degrees``)."""
    return radians * 180.0 / math.pi
