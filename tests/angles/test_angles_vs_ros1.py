"""``angles`` against Debian's python3-angles (ROS Noetic's angles 1.9 Python module), value for value.

The inputs include the edge cases that decide ties: exact multiples of pi, limits at +-pi, zero deltas,
angles beyond +-2*pi, and arcs that wrap through pi.
"""

from __future__ import annotations

import json
import math
import random
import subprocess
from pathlib import Path

import pytest

import angles
from ninjemys import testing

_DEBIAN = Path("/usr/lib/python3/dist-packages/angles/__init__.py")

_ORACLE = r"""
import json, sys
import angles
calls = json.loads(sys.stdin.read())
out = []
for name, args in calls:
    r = getattr(angles, name)(*args)
    out.append(list(r) if isinstance(r, tuple) else r)
print(json.dumps(out))
"""


def _calls() -> list[tuple[str, list[float]]]:
    rng = random.Random(21)
    pi = math.pi
    specials = [
        0.0,
        pi,
        -pi,
        2 * pi,
        -2 * pi,
        pi / 2,
        -pi / 2,
        0.25,
        -0.25,
        0.5,
        -0.5,
        3 * pi,
        -7.5,
        10.5 * pi,
    ]
    singles = specials + [rng.uniform(-20, 20) for _ in range(60)]
    pairs = [(a, b) for a in specials for b in specials] + [
        (rng.uniform(-10, 10), rng.uniform(-10, 10)) for _ in range(100)
    ]
    limits = [(-0.25, 0.25), (0.25, -0.25), (-pi, pi), (-pi / 2, pi / 2), (0.0, pi), (-pi, 0.0), (1.0, -2.0)]
    limits += [(rng.uniform(-pi, pi), rng.uniform(-pi, pi)) for _ in range(20)]
    large = [(-2 * pi, 2 * pi), (-2 * pi, 0.1 * pi), (-1.0, 5.0), (3.0, 1.0), (-pi, pi)]
    calls: list[tuple[str, list[float]]] = []
    for a in singles:
        calls += [("normalize_angle_positive", [a]), ("normalize_angle", [a]), ("two_pi_complement", [a])]
    for a, b in pairs:
        calls.append(("shortest_angular_distance", [a, b]))
    ends = [(-0.5, 0.5), (0.5, -0.5), (0.0, pi), (pi, 0.0), (0.1, 0.2), (3.0, -3.0), (0.25, -0.25)]
    ends += [(rng.uniform(-pi, pi), rng.uniform(-pi, pi)) for _ in range(25)]
    for lo, hi in limits:
        for a, b in ends:
            calls.append(("shortest_angular_distance_with_limits", [a, b, lo, hi]))
    for lo, hi in large:
        for a, b in ends + [(0.0, 10.5 * pi), (10.5 * pi, 0.0), (5.0, -5.0)]:
            calls.append(("shortest_angular_distance_with_large_limits", [a, b, lo, hi]))
    return calls


@pytest.mark.ros1
def test_every_function_matches_debian_python3_angles() -> None:
    if not (testing.have_ros1() and _DEBIAN.is_file()):
        pytest.skip("Debian's python3-angles is not installed")
    calls = _calls()
    done = subprocess.run(
        [testing.ROS1_PYTHON, "-c", _ORACLE],
        input=json.dumps(calls),
        capture_output=True,
        text=True,
        timeout=60,
        check=True,
        cwd="/",
    )
    theirs = json.loads(done.stdout)
    assert len(theirs) == len(calls)
    for (name, args), want in zip(calls, theirs, strict=True):
        got = getattr(angles, name)(*args)
        got = list(got) if isinstance(got, tuple) else got
        assert got == want, f"{name}{tuple(args)}: ours {got}, Debian's {want}"


def test_documented_examples() -> None:
    pi = math.pi
    assert angles.two_pi_complement(-pi / 4) == pytest.approx(7 * pi / 4)
    assert angles.two_pi_complement(pi / 4) == pytest.approx(-7 * pi / 4)
    assert angles.two_pi_complement(0.0) == pytest.approx(2 * pi)
    ok, delta = angles.shortest_angular_distance_with_limits(-0.5, 0.5, 0.25, -0.25)
    # the docstring upstream says 2*pi-1.0; the code (and Debian's) goes clockwise: -(2*pi-1.0)
    assert ok and delta == pytest.approx(-(2 * pi - 1.0))
    assert angles.shortest_angular_distance_with_limits(-0.5, 0.5, -0.25, 0.25)[0] is False
    ok, delta = angles.shortest_angular_distance_with_large_limits(0, 10.5 * pi, -2 * pi, 2 * pi)
    assert ok and delta == pytest.approx(0.5 * pi)
    ok, delta = angles.shortest_angular_distance_with_large_limits(0, 10.5 * pi, -2 * pi, 0.1 * pi)
    assert ok and delta == pytest.approx(-1.5 * pi)
    assert angles.shortest_angular_distance_with_large_limits(10.5 * pi, 0, -2 * pi, 2 * pi)[0] is False
    assert angles.shortest_angular_distance(0.1, 2 * pi - 0.1) == pytest.approx(-0.2)
    assert angles.to_degrees(angles.from_degrees(30.0)) == pytest.approx(30.0)
