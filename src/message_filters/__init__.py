"""ROS 1's ``message_filters``, as a facade over :mod:`ninjemys.message_filters`.

``Subscriber`` takes rospy.Subscriber's arguments (it subscribes through rospy, so it works after
``rospy.init_node``); the other filters are the core's. ``message_filters.tf2.MessageFilter`` is
tf2_ros' C++ MessageFilter for Python.
"""

from __future__ import annotations

from typing import Any

from ninjemys import message_filters as _core
from ninjemys.message_filters import (
    Cache,
    Chain,
    SimpleFilter,
    TimeSynchronizer,
    shared_subscriber,
)
from ninjemys.message_filters import _pass_on as _pass_on
from ninjemys.rostime import Duration

__all__ = [
    "ApproximateTimeSynchronizer",
    "Cache",
    "Chain",
    "SimpleFilter",
    "Subscriber",
    "TimeSynchronizer",
]


class ApproximateTimeSynchronizer(_core.ApproximateTimeSynchronizer):
    """``ApproximateTimeSynchronizer(fs, queue_size, slop, allow_headerless=False, reset=False)``;
    ``slop`` is kept as a ``rospy.Duration``, as ROS 1 keeps it."""

    def __init__(
        self,
        fs: Any,
        queue_size: int,
        slop: float,
        allow_headerless: bool = False,
        reset: bool = False,
    ) -> None:
        super().__init__(fs, queue_size, slop, allow_headerless, reset)
        self.slop = Duration.from_sec(slop)


class Subscriber(SimpleFilter):
    """A source filter with ``rospy.Subscriber``'s arguments; every message is passed on."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__()
        self.topic = args[0] if args else kwargs["name"]
        kwargs["callback"] = self.callback
        self.sub = _shared_rospy_subscriber()(*args, **kwargs)

    def callback(self, msg: Any) -> None:
        _pass_on(self, msg)

    def getTopic(self) -> str:  # noqa: N802 - ROS 1 API
        return self.topic

    def __getattr__(self, key: str) -> Any:
        """Everything else is rospy.Subscriber's (``unregister``, ``get_num_connections`` ...)."""
        if key == "sub":
            raise AttributeError(key)
        return getattr(self.sub, key)


def _shared_rospy_subscriber() -> type:
    """A ``rospy.Subscriber`` whose core subscription is made by :func:`shared_subscriber` (one thread
    for all message_filters Subscribers of the process); rospy is imported on first use."""
    global _SharedSubscriber
    if _SharedSubscriber is None:
        import rospy
        from rospy.msg import AnyMsg

        class SharedSubscriber(rospy.Subscriber):
            def _create(self, node: Any) -> Any:
                if self.data_class is AnyMsg:  # raw bytes: rospy's own adapter, on a thread of its own
                    return super()._create(node)
                return shared_subscriber(
                    node,
                    self._requested,
                    self.data_class,
                    self.callback,
                    callback_args=self.callback_args,
                    queue_size=self.queue_size,
                )

        _SharedSubscriber = SharedSubscriber
    return _SharedSubscriber


_SharedSubscriber: type | None = None
