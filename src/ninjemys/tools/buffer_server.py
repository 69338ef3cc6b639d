"""``rosrun tf2_ros buffer_server``: a tf2 buffer that other nodes query over an action.

As tf2_ros's C++ node: it listens to ``/tf`` and ``/tf_static`` into a buffer of ``~buffer_size``
seconds (120 by default) and serves ``tf2_buffer_server`` (``tf2_msgs/LookupTransform``). A goal is
answered at once when its transform is there (or its timeout is zero), else when it becomes available
or its timeout passes, whichever comes first. Every answered goal SUCCEEDS; a failed lookup is
reported in ``result.error`` (code and text), which ``tf2_ros.BufferClient`` raises as tf2's
exception. A cancelled goal that is still waiting is set canceled.
"""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING, Any

from ninjemys.actionlib.server import ActionServer
from ninjemys.tf2 import errors
from ninjemys.tools.cli import entry, wait_for_master_like_roscpp
from tf2_msgs.msg import LookupTransformAction, LookupTransformResult, TF2Error

if TYPE_CHECKING:
    from ninjemys.node import Node

#: tf2's exceptions -> the error code the result carries (checked in order: the most specific first)
_CODES = (
    (errors.ConnectivityException, TF2Error.CONNECTIVITY_ERROR),
    (errors.LookupException, TF2Error.LOOKUP_ERROR),
    (errors.ExtrapolationException, TF2Error.EXTRAPOLATION_ERROR),
    (errors.InvalidArgumentException, TF2Error.INVALID_ARGUMENT_ERROR),
    (errors.TimeoutException, TF2Error.TIMEOUT_ERROR),
)

#: seconds between checks of the goals still waiting (tf2_ros's check_period)
CHECK_PERIOD = 0.01


class BufferServer:
    """Serve lookups on ``buffer`` as the action ``ns`` of ``node``; call :meth:`start` when ready."""

    def __init__(self, node: Node, buffer: Any, ns: str, auto_start: bool = False) -> None:
        self.node = node
        self.buffer = buffer
        self._lock = threading.Lock()
        self._waiting: list[tuple[Any, float]] = []  # (goal handle, ROS time in s when it gives up)
        self.server = ActionServer(
            node, ns, LookupTransformAction, self._on_goal, self._on_cancel, auto_start
        )
        self._timer = node.timer(CHECK_PERIOD, self._check)

    def start(self) -> None:
        self.server.start()

    def _possible(self, goal: Any) -> bool:
        if goal.advanced:
            return bool(
                self.buffer.can_transform_full(
                    goal.target_frame, goal.target_time, goal.source_frame, goal.source_time, goal.fixed_frame
                )
            )
        return bool(self.buffer.can_transform(goal.target_frame, goal.source_frame, goal.source_time))

    def _answer(self, handle: Any) -> None:
        """Look the transform up and succeed the goal with it, or with the lookup's error."""
        goal = handle.get_goal()
        result = LookupTransformResult()
        try:
            if goal.advanced:
                result.transform = self.buffer.lookup_transform_full(
                    goal.target_frame, goal.target_time, goal.source_frame, goal.source_time, goal.fixed_frame
                )
            else:
                result.transform = self.buffer.lookup_transform(
                    goal.target_frame, goal.source_frame, goal.source_time
                )
        except errors.TransformException as exc:
            codes = (
                (errors.ConnectivityException, TF2Error.CONNECTIVITY_ERROR),
                (errors.LookupException, TF2Error.LOOKUP_ERROR),
                (errors.ExtrapolationException, TF2Error.EXTRAPOLATION_ERROR),
                (errors.InvalidArgumentException, TF2Error.INVALID_ARGUMENT_ERROR),
                (errors.TimeoutException, TF2Error.TIMEOUT_ERROR),
            )
            result.error.error = next(
                (code for kind, code in codes if isinstance(exc, kind)), TF2Error.TRANSFORM_ERROR
            )
            result.error.error_string = str(exc)
        handle.set_succeeded(result)

    def _on_goal(self, handle: Any) -> None:
        handle.set_accepted()
        goal = handle.get_goal()
        now = self.node.get_time()
        end = now + goal.timeout.to_sec()
        if end <= now or self._possible(goal):
            self._answer(handle)
            return
        with self._lock:
            self._waiting.append((handle, end))

    def _on_cancel(self, handle: Any) -> None:
        with self._lock:
            before = len(self._waiting)
            self._waiting = [(h, end) for h, end in self._waiting if h != handle]
            cancelled = len(self._waiting) != before
        if cancelled:
            handle.set_canceled()

    def _check(self, _event: Any) -> None:
        now = self.node.get_time()
        with self._lock:
            due = [(h, end) for h, end in self._waiting if end < now or self._possible(h.get_goal())]
            self._waiting = [item for item in self._waiting if item not in due]
        for handle, _end in due:
            self._answer(handle)


def main(argv: list[str] | None = None) -> int:
    from ninjemys.node.run import run_node

    return run_node("tf_buffer", argv, serve)


def serve(node: Node) -> int:
    """The buffer, its listener and the action server on a core node (a roscpp program in ROS 1)."""
    from ninjemys.tf2.buffer import Buffer
    from ninjemys.tf2.node import TransformListener

    if not wait_for_master_like_roscpp(node):
        return 0  # Ctrl-C while waiting for the master, as roscpp: a quiet exit
    buffer = Buffer(float(node.get_param("~buffer_size", 120.0)), now=node.get_time)
    TransformListener(node, buffer, now=node.get_time, report=node.log.warn)
    BufferServer(node, buffer, "tf2_buffer_server").start()
    return 0


console_main = entry(main)
