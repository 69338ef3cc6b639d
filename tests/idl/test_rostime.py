"""Time and Duration follow genpy's semantics."""

from __future__ import annotations

import pickle

import pytest

from ninjemys import rostime
from ninjemys.rostime import Duration, Time


def test_normalization_and_float_constructor() -> None:
    assert (Time(1, 1_500_000_000).secs, Time(1, 1_500_000_000).nsecs) == (2, 500_000_000)
    d = Duration(-1.5)
    assert (d.secs, d.nsecs) == (-2, 500_000_000)
    assert Duration(0, -1).to_nsec() == -1
    t = Time(1.25)
    assert (t.secs, t.nsecs) == (1, 250_000_000)
    with pytest.raises(TypeError):
        Time(-1)
    with pytest.raises(ValueError):
        Time(1.5, 3)


def test_conversions() -> None:
    assert Time(3, 500_000_000).to_sec() == 3.5
    assert Time(3, 5).to_nsec() == 3_000_000_005
    assert Time.from_sec(2.75) == Time(2, 750_000_000)
    assert Duration.from_sec(-0.5).to_sec() == -0.5
    assert Time().is_zero() and not Time(0, 1).is_zero()
    assert not Time() and Duration(1)
    assert str(Time(1, 2)) == "1000000002"
    assert repr(Duration(1)) == "rospy.Duration[1000000000]"


def test_arithmetic() -> None:
    assert Time(1, 600_000_000) + Duration(0, 500_000_000) == Time(2, 100_000_000)
    assert Duration(1) + Time(1) == Time(2)
    assert Time(3) - Time(1, 500_000_000) == Duration(1, 500_000_000)
    assert Time(3) - Duration(1) == Time(2)
    assert -Duration(1, 5) == Duration(-1, -5)
    assert abs(Duration(-2)) == Duration(2)
    assert Duration(2) * 3 == Duration(6) and 2 * Duration(1) == Duration(2)
    assert Duration(3) * 0.5 == Duration(1, 500_000_000)
    assert Duration(3) / 2 == Duration(1, 500_000_000)
    assert Duration(3) / Duration(2) == 1.5
    assert Duration(7) // Duration(2) == 3
    assert Duration(7) % Duration(2) == Duration(1)
    with pytest.raises(TypeError):
        Time(1) + Time(1)


def test_comparisons_and_hashing() -> None:
    assert Time(1) < Time(1, 1) <= Time(1, 1) and Time(2) > Time(1)
    assert Duration(-1) < Duration(0)
    assert Time(1) != Duration(1) and Time(1) != 1
    with pytest.raises(TypeError):
        _ = Time(1) < Duration(2)
    assert len({Time(1), Time(1, 0), Time(2)}) == 2
    assert pickle.loads(pickle.dumps(Time(4, 5))) == Time(4, 5)


def test_now_uses_the_pluggable_clock() -> None:
    try:
        rostime.set_clock(lambda: (42, 7))
        assert Time.now() == Time(42, 7)
    finally:
        rostime.set_clock(None)
    assert Time.now().secs > 1_600_000_000
