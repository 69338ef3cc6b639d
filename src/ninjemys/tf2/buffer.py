"""The message-level tf2 buffer: ``geometry_msgs/TransformStamped`` in and out, ROS times, timeouts.

:class:`Buffer` is tf2_py's ``BufferCore`` surface (``set_transform``, ``lookup_transform_core``,
``can_transform_core`` ...) plus tf2_ros's ``BufferInterface`` (``lookup_transform`` with a timeout,
the full forms, ``transform()`` through registered conversions) on :class:`~ninjemys.tf2.core.BufferCore`.
It knows no node: the clock that timeouts are measured on is passed in (ROS time for a node, wall
time by default). ``tf2_ros.Buffer`` is this class plus the ``~tf2_frames`` service.
"""

from __future__ import annotations

import copy
from collections.abc import Callable
from typing import Any

from ninjemys.idl.loader import get_message_class
from ninjemys.rostime import Time
from ninjemys.tf2.core import DEFAULT_CACHE_TIME, BufferCore, Reporter
from ninjemys.tf2.errors import TransformException

_new = object.__new__
_NS = 1_000_000_000


def to_ns(t: Any) -> int:
    """Integer nanoseconds of a ROS time or duration (anything with secs/nsecs or to_sec) or of seconds."""
    try:
        return t.secs * _NS + t.nsecs
    except AttributeError:
        pass
    if isinstance(t, (int, float)):
        return int(round(t * 1e9))
    if hasattr(t, "to_nsec"):
        return int(t.to_nsec())
    if hasattr(t, "to_sec"):
        return int(round(t.to_sec() * 1e9))
    raise TypeError("time must have a to_sec method, e.g. rospy.Time or rospy.Duration")


def to_seconds(d: Any) -> float:
    """Seconds of a duration given as a Duration, a number, or None (0)."""
    if d is None:
        return 0.0
    if isinstance(d, (int, float)):
        return float(d)
    return to_ns(d) / 1e9


def make_time(ns: int) -> Time:
    """A ``Time`` without the constructor's checks (the value is already normalized)."""
    t = _new(Time)
    t.secs, t.nsecs = divmod(ns, _NS)
    return t


class _Classes:
    """The geometry_msgs/std_msgs classes, loaded on first use (no work at import)."""

    loaded = False
    TransformStamped: Any
    Header: Any
    Transform: Any
    Vector3: Any
    Quaternion: Any

    @classmethod
    def load(cls) -> None:
        cls.TransformStamped = get_message_class("geometry_msgs/TransformStamped")
        cls.Header = get_message_class("std_msgs/Header")
        cls.Transform = get_message_class("geometry_msgs/Transform")
        cls.Vector3 = get_message_class("geometry_msgs/Vector3")
        cls.Quaternion = get_message_class("geometry_msgs/Quaternion")
        cls.loaded = True


def _builder() -> Callable[[str, str, int, tuple], Any]:
    """The function that builds a lookup's ``geometry_msgs/TransformStamped`` slot by slot, with the
    classes bound as locals (no constructor argument parsing, no global lookups: about 1 µs)."""
    c = _Classes
    if not c.loaded:
        c.load()

    def build(
        target: str,
        source: str,
        stamp_ns: int,
        t: tuple,
        new: Callable[[type], Any] = _new,
        stamped: type = c.TransformStamped,
        header: type = c.Header,
        time: type = Time,
        transform: type = c.Transform,
        vector3: type = c.Vector3,
        quaternion: type = c.Quaternion,
    ) -> Any:
        h = new(header)
        h.seq = 0
        stamp = new(time)
        stamp.secs, stamp.nsecs = divmod(stamp_ns, _NS)
        h.stamp = stamp
        h.frame_id = target
        v = new(vector3)
        v.x, v.y, v.z, qx, qy, qz, qw = t
        q = new(quaternion)
        q.x = qx
        q.y = qy
        q.z = qz
        q.w = qw
        tr = new(transform)
        tr.translation = v
        tr.rotation = q
        m = new(stamped)
        m.header = h
        m.child_frame_id = source
        m.transform = tr
        return m

    return build


_build: Callable[[str, str, int, tuple], Any] | None = None


def make_transform_stamped(target: str, source: str, stamp_ns: int, t: tuple) -> Any:
    """A ``geometry_msgs/TransformStamped`` for a lookup's result (classes loaded on first use)."""
    global _build
    if _build is None:
        _build = _builder()
    return _build(target, source, stamp_ns, t)


def transform_tuple(msg: Any) -> tuple[float, float, float, float, float, float, float]:
    """The 7 floats of a ``geometry_msgs/Transform``."""
    v = msg.translation
    q = msg.rotation
    return (float(v.x), float(v.y), float(v.z), float(q.x), float(q.y), float(q.z), float(q.w))


class TypeException(TransformException):
    """No conversion is registered for a type (tf2_ros's ``TypeException``; ``errstr`` kept)."""

    def __init__(self, errstr: str) -> None:
        super().__init__(errstr)
        self.errstr = errstr


class TransformRegistration:
    """Per type, the function that applies a TransformStamped to a stamped object (shared by all instances)."""

    _type_map: dict[type, Callable[[Any, Any], Any]] = {}

    def add(self, key: type, callback: Callable[[Any, Any], Any]) -> None:
        TransformRegistration._type_map[key] = callback

    def get(self, key: type) -> Callable[[Any, Any], Any]:
        try:
            return TransformRegistration._type_map[key]
        except KeyError:
            raise TypeException(f"Type {key} if not loaded or supported") from None

    def print_me(self) -> None:
        print(TransformRegistration._type_map)


class ConvertRegistration:
    """to_msg / from_msg / direct conversions between data types (tf2_ros's ``ConvertRegistration``)."""

    _to_msg: dict[type, Callable[[Any], Any]] = {}
    _from_msg: dict[type, Callable[[Any], Any]] = {}
    _convert: dict[tuple[type, type], Callable[[Any], Any]] = {}

    def add_to_msg(self, key: type, callback: Callable[[Any], Any]) -> None:
        ConvertRegistration._to_msg[key] = callback

    def add_from_msg(self, key: type, callback: Callable[[Any], Any]) -> None:
        ConvertRegistration._from_msg[key] = callback

    def add_convert(self, key: tuple[type, type], callback: Callable[[Any], Any]) -> None:
        ConvertRegistration._convert[key] = callback

    @staticmethod
    def _get(table: dict, key: Any) -> Callable[[Any], Any]:
        try:
            return table[key]
        except KeyError:
            raise TypeException(f"Type {key} if not loaded or supported") from None

    def get_to_msg(self, key: type) -> Callable[[Any], Any]:
        return self._get(ConvertRegistration._to_msg, key)

    def get_from_msg(self, key: type) -> Callable[[Any], Any]:
        return self._get(ConvertRegistration._from_msg, key)

    def get_convert(self, key: tuple[type, type]) -> Callable[[Any], Any]:
        return self._get(ConvertRegistration._convert, key)


def convert(a: Any, b_type: type) -> Any:
    """``a`` as ``b_type``: a direct conversion if registered, a copy for the same type, else via the message."""
    reg = ConvertRegistration()
    try:
        return reg.get_convert((type(a), b_type))(a)
    except TypeException:
        if type(a) is b_type:
            return copy.deepcopy(a)
        return reg.get_from_msg(b_type)(reg.get_to_msg(type(a))(a))


class Buffer(BufferCore):
    """tf2's buffer with ROS messages and times; ``now`` is the clock timeouts run on (seconds)."""

    def __init__(
        self,
        cache_time: Any = None,
        now: Callable[[], float] | None = None,
        report: Reporter | None = None,
    ) -> None:
        super().__init__(DEFAULT_CACHE_TIME if cache_time is None else to_seconds(cache_time), report)
        self._now = now
        self.registration = TransformRegistration()

    # -- tf2_py's BufferCore ---------------------------------------------------------------------
    def set_transform(self, transform: Any, authority: str = "default_authority") -> bool:
        """Insert a ``TransformStamped`` (bad ones are reported in one line and dropped)."""
        return self._set(transform, authority, False)

    def set_transform_static(self, transform: Any, authority: str = "default_authority") -> bool:
        """Insert a ``TransformStamped`` that holds for all time."""
        return self._set(transform, authority, True)

    def _set(self, m: Any, authority: str, is_static: bool) -> bool:
        h = m.header
        item = (h.frame_id, m.child_frame_id, to_ns(h.stamp), *transform_tuple(m.transform))
        return self.set_transforms((item,), authority, is_static) == 1

    def lookup_transform_core(self, target_frame: str, source_frame: str, time: Any) -> Any:
        stamp, t = self.lookup(target_frame, source_frame, to_ns(time))
        return make_transform_stamped(target_frame, source_frame, stamp, t)

    def lookup_transform_full_core(
        self, target_frame: str, target_time: Any, source_frame: str, source_time: Any, fixed_frame: str
    ) -> Any:
        stamp, t = self.lookup_full(
            target_frame, to_ns(target_time), source_frame, to_ns(source_time), fixed_frame
        )
        return make_transform_stamped(target_frame, source_frame, stamp, t)

    def can_transform_core(self, target_frame: str, source_frame: str, time: Any) -> tuple[bool, str]:
        return self.can_transform_ns(target_frame, source_frame, to_ns(time))

    def can_transform_ns(self, target_frame: str, source_frame: str, t: int) -> tuple[bool, str]:
        return BufferCore.can_transform(self, target_frame, source_frame, t)

    def can_transform_full_core(
        self, target_frame: str, target_time: Any, source_frame: str, source_time: Any, fixed_frame: str
    ) -> tuple[bool, str]:
        return BufferCore.can_transform_full(
            self, target_frame, to_ns(target_time), source_frame, to_ns(source_time), fixed_frame
        )

    def get_latest_common_time(self, target_frame: str, source_frame: str) -> Time:
        return make_time(self.latest_common_time(target_frame, source_frame))

    def _allFramesAsDot(self, current_time: Any = None) -> str:  # noqa: N802 (tf2_py's name)
        return self.all_frames_as_dot(0.0 if current_time is None else to_seconds(current_time))

    def _chain(  # tf2_py's name
        self, target_frame: str, target_time: Any, source_frame: str, source_time: Any, fixed_frame: str
    ) -> list[str]:
        return self.chain(target_frame, to_ns(target_time), source_frame, to_ns(source_time), fixed_frame)

    def _frameExists(self, frame_id: str) -> bool:  # noqa: N802
        return self.frame_exists(frame_id)

    def _getFrameStrings(self) -> list[str]:  # noqa: N802
        return self.frame_names()

    # -- tf2_ros's BufferInterface ---------------------------------------------------------------
    def _wait(self, check: Callable[[], tuple[bool, str]], timeout: Any) -> tuple[bool, str]:
        seconds = to_seconds(timeout)
        if seconds <= 0.0:
            return check()
        return self.wait_for_transform(check, seconds, self._now, self._cancelled)

    def _cancelled(self) -> bool:
        """Whether a wait should give up early (a node facade says so at shutdown)."""
        return False

    def lookup_transform(self, target_frame: str, source_frame: str, time: Any, timeout: Any = None) -> Any:
        """The transform from ``source_frame`` to ``target_frame`` at ``time`` (0 = latest common), waiting
        up to ``timeout`` for it to become available; raises tf2's exceptions."""
        try:
            t = time.secs * _NS + time.nsecs
        except AttributeError:
            t = to_ns(time)
        try:
            stamp, tr = self.lookup(target_frame, source_frame, t)
        except TransformException:
            if timeout is None or to_seconds(timeout) <= 0.0:
                raise
            # not yet: wait for it (as tf2_ros's can_transform with the timeout), then look again
            self._wait(lambda: self.can_transform_ns(target_frame, source_frame, t), timeout)
            stamp, tr = self.lookup(target_frame, source_frame, t)
        return (_build or make_transform_stamped)(target_frame, source_frame, stamp, tr)

    def lookup_transform_full(
        self,
        target_frame: str,
        target_time: Any,
        source_frame: str,
        source_time: Any,
        fixed_frame: str,
        timeout: Any = None,
    ) -> Any:
        """The advanced lookup: ``source_frame`` at ``source_time`` into ``target_frame`` at ``target_time``,
        treating ``fixed_frame`` as constant in time."""
        if timeout is not None and to_seconds(timeout) > 0.0:
            self.can_transform_full(
                target_frame, target_time, source_frame, source_time, fixed_frame, timeout
            )
        return self.lookup_transform_full_core(
            target_frame, target_time, source_frame, source_time, fixed_frame
        )

    def can_transform(
        self,
        target_frame: str,
        source_frame: str,
        time: Any,
        timeout: Any = None,
        return_debug_tuple: bool = False,
    ) -> Any:
        """Whether the lookup would succeed, waiting up to ``timeout``; ``(bool, why)`` on request."""
        t = to_ns(time)
        if timeout is None or to_seconds(timeout) <= 0.0:
            result = BufferCore.can_transform(self, target_frame, source_frame, t)
        else:
            result = self._wait(lambda: self.can_transform_ns(target_frame, source_frame, t), timeout)
        return result if return_debug_tuple else result[0]

    def can_transform_full(
        self,
        target_frame: str,
        target_time: Any,
        source_frame: str,
        source_time: Any,
        fixed_frame: str,
        timeout: Any = None,
        return_debug_tuple: bool = False,
    ) -> Any:
        """The advanced form of :meth:`can_transform`."""
        tt, st = to_ns(target_time), to_ns(source_time)
        result = self._wait(
            lambda: BufferCore.can_transform_full(self, target_frame, tt, source_frame, st, fixed_frame),
            timeout,
        )
        return result if return_debug_tuple else result[0]

    def transform(
        self, object_stamped: Any, target_frame: str, timeout: Any = None, new_type: type | None = None
    ) -> Any:
        """``object_stamped`` (any registered stamped type) expressed in ``target_frame``."""
        do_transform = self.registration.get(type(object_stamped))
        h = object_stamped.header
        res = do_transform(object_stamped, self.lookup_transform(target_frame, h.frame_id, h.stamp, timeout))
        return res if new_type is None else convert(res, new_type)

    def transform_full(
        self,
        object_stamped: Any,
        target_frame: str,
        target_time: Any,
        fixed_frame: str,
        timeout: Any = None,
        new_type: type | None = None,
    ) -> Any:
        """:meth:`transform` through ``fixed_frame``, to ``target_time``."""
        do_transform = self.registration.get(type(object_stamped))
        h = object_stamped.header
        tr = self.lookup_transform_full(target_frame, target_time, h.frame_id, h.stamp, fixed_frame, timeout)
        res = do_transform(object_stamped, tr)
        return res if new_type is None else convert(res, new_type)


__all__ = [
    "Buffer",
    "ConvertRegistration",
    "TransformRegistration",
    "TypeException",
    "convert",
    "make_time",
    "make_transform_stamped",
    "to_ns",
    "to_seconds",
    "transform_tuple",
]
