"""ROS 1's ``tf2_ros`` Python API over :mod:`ninjemys.tf2` (a facade: the logic lives there).

``Buffer``, ``TransformListener``, ``TransformBroadcaster`` and ``StaticTransformBroadcaster`` work after
``rospy.init_node()`` on the process's core Node. Timeouts run on ROS time and wait on the buffer's
condition (new data wakes them), not on polling sleeps. ``BufferClient`` (lookups answered by
``rosrun tf2_ros buffer_server`` over an action) loads on first use.
"""

from __future__ import annotations

import logging
import time as _time
from collections.abc import Callable
from typing import Any

from ninjemys.tf2 import node as _tfnode
from ninjemys.tf2.buffer import (
    ConvertRegistration,
    TransformRegistration,
    TypeException,
    convert,
)
from ninjemys.tf2.errors import (
    ConnectivityException,
    ExtrapolationException,
    InvalidArgumentException,
    LookupException,
    TimeoutException,
    TransformException,
)
from tf2_py import BufferCore

_log = logging.getLogger("tf2_ros")

#: ROS 1's polling step for timed can_transform, as a fraction of the timeout; ours waits on the
#: buffer's condition instead (new data wakes it), the name stays for code that reads it
DEFAULT_CAN_TRANSFORM_POLLING_SCALE = 0.01

#: names loaded on first use: BufferClient, and the message classes ROS 1's tf2_ros namespace carries
#: along (its star imports)
_LAZY_NAMES = {
    "BufferClient": ("tf2_ros.buffer_client", "BufferClient"),
    "TransformStamped": ("geometry_msgs.msg", "TransformStamped"),
    "TFMessage": ("tf2_msgs.msg", "TFMessage"),
    "Header": ("std_msgs.msg", "Header"),
    "FrameGraph": ("tf2_msgs.srv", "FrameGraph"),
    "FrameGraphResponse": ("tf2_msgs.srv", "FrameGraphResponse"),
    "GoalStatus": ("actionlib_msgs.msg", "GoalStatus"),
    "LookupTransformAction": ("tf2_msgs.msg", "LookupTransformAction"),
    "LookupTransformGoal": ("tf2_msgs.msg", "LookupTransformGoal"),
}


def __getattr__(name: str) -> Any:
    import importlib

    if name == "buffer_client":  # loads actionlib and rospy: only when asked for
        return importlib.import_module("tf2_ros.buffer_client")
    spec = _LAZY_NAMES.get(name)
    if spec is None:
        raise AttributeError(f"module 'tf2_ros' has no attribute {name!r}")
    value = getattr(importlib.import_module(spec[0]), spec[1])
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_LAZY_NAMES, "buffer_client"})


def _lazy_messages(
    module: str, names: tuple[str, ...]
) -> tuple[Callable[[str], Any], Callable[[], list[str]]]:
    """``__getattr__`` and ``__dir__`` for a submodule that carries message classes as ROS 1's does,
    loaded on first use like the package's (``import tf2_ros`` loads every submodule, and a stub
    package reads no definition file until a name is used)."""
    import sys

    def getattr_(name: str) -> Any:
        if name not in names:
            raise AttributeError(f"module {module!r} has no attribute {name!r}")
        value = __getattr__(name)
        setattr(sys.modules[module], name, value)
        return value

    return getattr_, lambda: sorted({*vars(sys.modules[module]), *names})


def _rospy() -> Any:
    import rospy

    return rospy


def _ros_now() -> float:
    """ROS time in seconds once ``init_node`` ran (sim time included), wall time before."""
    rospy = _rospy()
    if rospy.core.is_initialized():
        return rospy.get_time()
    return _time.time()


def _report_error(line: str) -> None:
    rospy = _rospy()
    if rospy.core.is_initialized():
        rospy.logerr(line)
    else:
        _log.error(line)


def _report_warn(line: str) -> None:
    rospy = _rospy()
    if rospy.core.is_initialized():
        rospy.logwarn(line)
    else:
        _log.warning(line)


class NotImplementedException(Exception):
    """A BufferInterface method a subclass did not implement."""

    def __init__(self) -> None:
        super().__init__("CanTransform or LookupTransform not implemented")
        self.errstr = "CanTransform or LookupTransform not implemented"


class BufferInterface:
    """The abstract tf2_ros buffer API; :class:`Buffer` implements it (``transform`` comes from there)."""

    def __init__(self) -> None:
        self.registration = TransformRegistration()

    def transform(
        self, object_stamped: Any, target_frame: str, timeout: Any = None, new_type: Any = None
    ) -> Any:
        do_transform = self.registration.get(type(object_stamped))
        h = object_stamped.header
        res = do_transform(object_stamped, self.lookup_transform(target_frame, h.frame_id, h.stamp, timeout))
        return res if not new_type else convert(res, new_type)

    def transform_full(
        self,
        object_stamped: Any,
        target_frame: str,
        target_time: Any,
        fixed_frame: str,
        timeout: Any = None,
        new_type: Any = None,
    ) -> Any:
        do_transform = self.registration.get(type(object_stamped))
        h = object_stamped.header
        tr = self.lookup_transform_full(target_frame, target_time, h.frame_id, h.stamp, fixed_frame, timeout)
        res = do_transform(object_stamped, tr)
        return res if not new_type else convert(res, new_type)

    def lookup_transform(self, target_frame: str, source_frame: str, time: Any, timeout: Any = None) -> Any:
        raise NotImplementedException()

    def lookup_transform_full(
        self,
        target_frame: str,
        target_time: Any,
        source_frame: str,
        source_time: Any,
        fixed_frame: str,
        timeout: Any = None,
    ) -> Any:
        raise NotImplementedException()

    def can_transform(self, target_frame: str, source_frame: str, time: Any, timeout: Any = None) -> Any:
        raise NotImplementedException()

    def can_transform_full(
        self,
        target_frame: str,
        target_time: Any,
        source_frame: str,
        source_time: Any,
        fixed_frame: str,
        timeout: Any = None,
    ) -> Any:
        raise NotImplementedException()


class Buffer(BufferCore, BufferInterface):
    """``tf2_ros.Buffer(cache_time=None, debug=True)``; with ``debug`` (and a node) it offers ``~tf2_frames``."""

    def __init__(self, cache_time: Any = None, debug: bool = True) -> None:
        BufferCore.__init__(self, cache_time)
        BufferInterface.__init__(self)
        self._now = _ros_now
        self._report = _report_error
        self.frame_server = None
        rospy = _rospy()
        if debug and rospy.core.is_initialized():
            self.frame_server = _tfnode.advertise_frames_service(rospy.core.process_node(), self)

    def _cancelled(self) -> bool:
        return _rospy().is_shutdown()


class TransformListener:
    """Fills ``buffer`` from ``/tf`` and ``/tf_static`` (needs ``rospy.init_node`` first)."""

    def __init__(
        self, buffer: Any, queue_size: int | None = None, buff_size: int = 65536, tcp_nodelay: bool = False
    ):
        rospy = _rospy()
        self.buffer = buffer
        self._core = _tfnode.TransformListener(
            rospy.core.process_node(),
            buffer,
            queue_size=queue_size,
            tcp_nodelay=tcp_nodelay,
            now=_ros_now,
            report=_report_warn,
        )
        self.tf_sub = self._core.tf_sub
        self.tf_static_sub = self._core.tf_static_sub

    def unregister(self) -> None:
        """Unsubscribe from ``/tf`` and ``/tf_static``."""
        self._core.unregister()

    def check_for_reset(self) -> None:
        """Clear the buffer when ROS time jumped back since the last message (a bag loop, a sim reset)."""
        self._core._check_for_reset()

    def callback(self, data: Any) -> None:
        """Add a ``tf2_msgs/TFMessage`` as if it came on ``/tf`` (authority: its publisher, if known)."""
        self.check_for_reset()
        who = (getattr(data, "_connection_header", None) or {}).get("callerid", "default_authority")
        for transform in data.transforms:
            self.buffer.set_transform(transform, who)

    def static_callback(self, data: Any) -> None:
        """Add a ``tf2_msgs/TFMessage`` as if it came on ``/tf_static``."""
        self.check_for_reset()
        who = (getattr(data, "_connection_header", None) or {}).get("callerid", "default_authority")
        for transform in data.transforms:
            self.buffer.set_transform_static(transform, who)


class TransformBroadcaster(_tfnode.TransformBroadcaster):
    """Sends transforms on ``/tf``: ``sendTransform(transform_or_list)``."""

    def __init__(self, queue_size: int = 100) -> None:
        super().__init__(_rospy().core.process_node(), queue_size)


class StaticTransformBroadcaster(_tfnode.StaticTransformBroadcaster):
    """Sends static transforms on the latched ``/tf_static``, keeping every frame it was given."""

    def __init__(self, queue_size: int = 100) -> None:
        super().__init__(_rospy().core.process_node(), queue_size)


def Stamped(obj: Any, stamp: Any, frame_id: str) -> Any:  # noqa: N802 (ROS 1's name)
    """Give ``obj`` a ``std_msgs/Header`` with ``stamp`` and ``frame_id``; returns ``obj``."""
    from std_msgs.msg import Header

    obj.header = Header(frame_id=frame_id, stamp=stamp)
    return obj


__all__ = [
    "Buffer",
    "BufferCore",
    "BufferInterface",
    "ConnectivityException",
    "ConvertRegistration",
    "ExtrapolationException",
    "InvalidArgumentException",
    "LookupException",
    "NotImplementedException",
    "Stamped",
    "StaticTransformBroadcaster",
    "TimeoutException",
    "TransformBroadcaster",
    "TransformException",
    "TransformListener",
    "TransformRegistration",
    "TypeException",
    "convert",
]


# ROS 1's ``import tf2_ros`` loads its submodules too (``tf2_ros.buffer.Buffer`` works after it);
# importing one binds it as an attribute of this package
def _load_submodules() -> None:
    import importlib

    for name in (
        "buffer",
        "buffer_interface",
        "static_transform_broadcaster",
        "transform_broadcaster",
        "transform_listener",
    ):
        importlib.import_module(f"tf2_ros.{name}")


_load_submodules()
