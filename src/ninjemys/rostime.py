"""ROS time values: :class:`Time` (a point in time) and :class:`Duration` (a signed span).

Semantics follow genpy's ``Time``/``Duration`` exactly, because user code and message equality depend
on them: values are kept as integer ``secs``/``nsecs`` normalized so that ``0 <= nsecs < 1e9``
(a negative duration of -1.5 s is ``secs=-2, nsecs=500000000``); a float passed as ``secs`` is split
into seconds and nanoseconds; arithmetic is exact on nanoseconds; comparing a Time with a Duration is a
TypeError, equality with another type is simply False.

``Time.now()`` reads the process's *default clock*: the clock of the node that claimed it
(:func:`claim_default_clock`; the first ``ninjemys.node.Node`` of the process, or rospy's node), so a
library calling ``Time.now()`` inside a simulated-time node gets simulated time; with no such node it
is the wall clock. Each Node owns its own clock (``node.now()``); this module only remembers which one
``Time.now()`` follows, without knowing anything about nodes.
"""

from __future__ import annotations

import time as _time
from collections.abc import Callable
from numbers import Integral, Real

TYPE_CHECKING = False  # importing typing costs start-up time; checkers set it
if TYPE_CHECKING:
    from typing import Self

_NS = 1_000_000_000

#: returns (secs, nsecs) of "now" for Time.now(); None is the wall clock (the fast path)
_clock: Callable[[], tuple[int, int]] | None = None
#: the node whose clock Time.now() follows (None: no node claimed it)
_owner: object | None = None


def _wall_clock() -> tuple[int, int]:
    ns = _time.time_ns()
    return ns // _NS, ns % _NS


def set_clock(clock: Callable[[], tuple[int, int]] | None) -> None:
    """Install the function that ``Time.now()`` uses (``None`` restores the wall clock)."""
    global _clock
    _clock = clock


def claim_default_clock(owner: object, clock: Callable[[], tuple[int, int]] | None) -> None:
    """Make ``clock`` (None: the wall clock) the one ``Time.now()`` reads, on behalf of ``owner``."""
    global _clock, _owner
    _owner = owner
    _clock = clock


def release_default_clock(owner: object) -> None:
    """``owner`` is going away: if it holds the default clock, ``Time.now()`` reverts to wall time."""
    global _clock, _owner
    if _owner is owner:
        _owner = None
        _clock = None


def default_clock_owner() -> object | None:
    """The node whose clock ``Time.now()`` reads, if one claimed it."""
    return _owner


def get_clock() -> Callable[[], tuple[int, int]]:
    """The clock ``Time.now()`` currently uses."""
    return _clock or _wall_clock


class TVal:
    """Common base of Time and Duration: integer secs/nsecs, normalized nanoseconds."""

    __slots__ = ("secs", "nsecs")

    def __init__(self, secs: int | float = 0, nsecs: int = 0) -> None:
        if not isinstance(secs, Integral):
            if nsecs != 0:
                raise ValueError("if secs is a float, nsecs cannot be set")
            whole = int(secs)
            nsecs = int((secs - whole) * 1e9)
            secs = whole
        else:
            secs = int(secs)
            nsecs = int(nsecs)
        carry, self.nsecs = divmod(nsecs, _NS)
        self.secs = secs + carry

    @classmethod
    def _raw(cls, secs: int, nsecs: int) -> Self:  # generated code's fast constructor
        """Build a value from wire integers without re-validating (normalizes if needed)."""
        obj = cls.__new__(cls)
        if 0 <= nsecs < _NS:
            obj.secs = secs
            obj.nsecs = nsecs
        else:
            carry, obj.nsecs = divmod(nsecs, _NS)
            obj.secs = secs + carry
        return obj

    def canon(self) -> None:
        """Normalize in place so that 0 <= nsecs < 1e9 (genpy API)."""
        carry, self.nsecs = divmod(self.nsecs, _NS)
        self.secs += carry

    def set(self, secs: int, nsecs: int) -> None:
        self.secs = secs
        self.nsecs = nsecs

    def is_zero(self) -> bool:
        return self.secs == 0 and self.nsecs == 0

    def to_sec(self) -> float:
        return float(self.secs) + float(self.nsecs) / 1e9

    def to_nsec(self) -> int:
        return self.secs * _NS + self.nsecs

    @classmethod
    def from_sec(cls, float_secs: float) -> Self:
        secs = int(float_secs)
        return cls(secs, int((float_secs - secs) * 1e9))

    def __bool__(self) -> bool:
        return not self.is_zero()

    def __str__(self) -> str:
        return str(self.to_nsec())

    def __hash__(self) -> int:
        return hash((self.secs, self.nsecs))

    def __getstate__(self) -> list[int]:
        return [self.secs, self.nsecs]

    def __setstate__(self, state: list[int]) -> None:
        self.secs, self.nsecs = state

    def __copy__(self) -> Self:
        return type(self)._raw(self.secs, self.nsecs)

    def __deepcopy__(self, memo: dict) -> Self:
        return type(self)._raw(self.secs, self.nsecs)

    def _cmp_check(self, other: object) -> int:
        if type(other) is not type(self) and not isinstance(other, type(self)):
            raise TypeError(f"cannot compare {type(self).__name__} to {type(other).__name__}")
        return other.to_nsec()

    def __lt__(self, other: object) -> bool:
        return self.to_nsec() < self._cmp_check(other)

    def __le__(self, other: object) -> bool:
        return self.to_nsec() <= self._cmp_check(other)

    def __gt__(self, other: object) -> bool:
        return self.to_nsec() > self._cmp_check(other)

    def __ge__(self, other: object) -> bool:
        return self.to_nsec() >= self._cmp_check(other)

    def __ne__(self, other: object) -> bool:
        return not self.__eq__(other)


class Time(TVal):
    """A point in time (seconds since the epoch, or since simulation start). Never negative."""

    __slots__ = ()  # TVal's layout; the visible __slots__ is set below the classes

    def __init__(self, secs: int | float = 0, nsecs: int = 0) -> None:
        super().__init__(secs, nsecs)
        if self.secs < 0:
            raise TypeError("time values must be positive")

    @classmethod
    def now(cls) -> Time:
        """The current time of this process's clock (wall clock, or /clock under use_sim_time)."""
        secs, nsecs = (_clock or _wall_clock)()
        return cls._raw(secs, nsecs)

    @classmethod
    def from_seconds(cls, float_secs: float) -> Time:
        """rospy's alias of :meth:`from_sec`."""
        return cls.from_sec(float_secs)

    def to_time(self) -> float:
        """genpy's alias of :meth:`to_sec` (``time.time()``'s format; rosbag scripts call it)."""
        return self.to_sec()

    def __repr__(self) -> str:
        return f"rospy.Time[{self.to_nsec()}]"

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Time):
            return False
        return self.secs == other.secs and self.nsecs == other.nsecs

    __hash__ = TVal.__hash__

    def __add__(self, other: object) -> Time:
        if not isinstance(other, Duration):
            return NotImplemented
        return Time._raw(self.secs + other.secs, self.nsecs + other.nsecs)

    __radd__ = __add__

    def __sub__(self, other: object) -> Time | Duration:
        if isinstance(other, Time):
            return Duration._raw(self.secs - other.secs, self.nsecs - other.nsecs)
        if isinstance(other, Duration):
            return Time._raw(self.secs - other.secs, self.nsecs - other.nsecs)
        return NotImplemented


class Duration(TVal):
    """A signed span of time."""

    __slots__ = ()  # TVal's layout; the visible __slots__ is set below the classes

    def __repr__(self) -> str:
        return f"rospy.Duration[{self.to_nsec()}]"

    @classmethod
    def from_seconds(cls, float_secs: float) -> Duration:
        return cls.from_sec(float_secs)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Duration):
            return False
        return self.secs == other.secs and self.nsecs == other.nsecs

    __hash__ = TVal.__hash__

    def __neg__(self) -> Duration:
        return Duration._raw(-self.secs, -self.nsecs)

    def __abs__(self) -> Duration:
        return self if self.secs >= 0 else -self

    def __add__(self, other: object) -> Duration | Time:
        if isinstance(other, Time):
            return other.__add__(self)
        if isinstance(other, Duration):
            return Duration._raw(self.secs + other.secs, self.nsecs + other.nsecs)
        return NotImplemented

    __radd__ = __add__

    def __sub__(self, other: object) -> Duration:
        if not isinstance(other, Duration):
            return NotImplemented
        return Duration._raw(self.secs - other.secs, self.nsecs - other.nsecs)

    def __mul__(self, val: object) -> Duration:
        if isinstance(val, Integral):
            return Duration._raw(self.secs * int(val), self.nsecs * int(val))
        if isinstance(val, Real):
            return Duration.from_sec(self.to_sec() * float(val))
        return NotImplemented

    __rmul__ = __mul__

    def __floordiv__(self, val: object) -> Duration | int:
        if isinstance(val, Integral):
            return Duration._raw(0, self.to_nsec() // int(val))
        if isinstance(val, Real):
            return Duration.from_sec(self.to_sec() // float(val))
        if isinstance(val, Duration):
            return self.to_nsec() // val.to_nsec()
        return NotImplemented

    def __truediv__(self, val: object) -> Duration | float:
        if isinstance(val, Integral | Real):
            return Duration.from_sec(self.to_sec() / float(val))
        if isinstance(val, Duration):
            return self.to_sec() / val.to_sec()
        return NotImplemented

    def __mod__(self, val: object) -> Duration:
        if not isinstance(val, Duration):
            return NotImplemented
        return Duration._raw(0, self.to_nsec() % val.to_nsec())

    def __divmod__(self, val: object) -> tuple[int, Duration]:
        if not isinstance(val, Duration):
            return NotImplemented
        q, r = divmod(self.to_nsec(), val.to_nsec())
        return q, Duration._raw(0, r)


# genpy's Time and Duration name their fields in their own __slots__, and code that walks a message
# through ``type(value).__slots__`` (rosbag-to-CSV exporters) reaches a stamp's secs and nsecs that
# way: with an empty tuple, stamps vanished from its output. Set after the classes are made, so that
# the instances keep TVal's layout (no second pair of slots: 48 bytes a stamp, not 64).
Time.__slots__ = Duration.__slots__ = TVal.__slots__  # type: ignore[assignment]
